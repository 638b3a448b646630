#pragma once
// Seed inputs for the protocol fuzzers: every sample message encoded (plain and tagged), plus
// upload programs that complete, corrupt and fragment an upload.
#include <string>
#include <vector>

#include "protocol/messages.h"
#include "tests/protocol/samples.h"

namespace hapticd::proto::testing {

inline std::vector<std::vector<std::uint8_t>> fuzzSeeds(const std::string& target) {
  std::vector<std::vector<std::uint8_t>> out;
  if (target == "upload") {
    // begin total = 10000, then chunks of 1000 in order, commit, missing
    auto program = [](std::size_t total, std::size_t chunk, bool corrupt) {
      std::vector<std::uint8_t> p;
      auto op = [&](std::uint8_t o) {
        p.push_back(1);  // time step
        p.push_back(o);
      };
      op(0);
      p.push_back(static_cast<std::uint8_t>((total - 1) & 0xff));
      p.push_back(static_cast<std::uint8_t>((total - 1) >> 8));
      p.push_back(0);
      p.push_back(0);
      for (std::size_t off = 0; off < total; off += chunk) {
        op(1);
        p.push_back(static_cast<std::uint8_t>(off & 0xff));
        p.push_back(static_cast<std::uint8_t>(off >> 8));
        p.push_back(static_cast<std::uint8_t>(chunk & 0xff));
        p.push_back(static_cast<std::uint8_t>(chunk >> 8));
        p.push_back(corrupt && off == chunk ? 0x5a : 0);
        op(3);
        p.push_back(8);
      }
      op(2);
      return p;
    };
    out.push_back(program(10000, 1000, false));
    out.push_back(program(4097, 1200, false));
    out.push_back(program(10000, 1000, true));
    out.push_back(program(60000, 4000, false));
    return out;
  }
  std::vector<std::uint8_t> buf(kMaxDatagramLimit);
  for (const auto& m : sampleMessages()) {
    Header h;
    h.session_id = 3;
    h.sequence = 4;
    const std::size_t n = encode(h, m, buf);
    std::vector<std::uint8_t> d(buf.begin(), buf.begin() + static_cast<long>(n));
    if (target == "messages") {
      out.push_back(d);
      // the payload alone, behind a type byte and a minor byte
      std::vector<std::uint8_t> p{static_cast<std::uint8_t>(typeOf(m)), kVersionMinor};
      p.insert(p.end(), d.begin() + static_cast<long>(kHeaderSize), d.end());
      out.push_back(p);
      if (typeOf(m) == MsgType::kState) {
        // a 1.0 State (no minor-1 tail) and a 1.2 one (a longer tail), whole and as payloads
        auto v10 = d;
        v10.resize(v10.size() - State::kMinor1Size);
        v10[5] = 0;
        const auto n10 = static_cast<std::uint32_t>(v10.size() - kHeaderSize);
        for (std::size_t i = 0; i < 4; ++i)
          v10[12 + i] = static_cast<std::uint8_t>(n10 >> (8 * i));
        out.push_back(v10);
        // the payload behind its two bytes: reuse the header's last two bytes' room
        std::vector<std::uint8_t> p10(v10.begin() + static_cast<long>(kHeaderSize) - 2, v10.end());
        p10[0] = static_cast<std::uint8_t>(MsgType::kState);
        p10[1] = 0;
        out.push_back(p10);
        auto p12 = p;
        p12[1] = 2;
        p12.resize(p12.size() + 16, 0x5a);
        out.push_back(p12);
      }
    } else {
      d.resize(std::min<std::size_t>(d.size(), kHeaderSize + 8));
      out.push_back(d);
    }
  }
  return out;
}

}  // namespace hapticd::proto::testing
