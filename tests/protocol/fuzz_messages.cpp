// libFuzzer target: every message decoder. The input is a whole datagram (decode()), and also,
// from its first two bytes, a type and a minor version for decodePayload() on the rest. A message
// that decodes must encode again and decode to an equal message.
#include <cstdint>
#include <span>
#include <vector>

#include "protocol/messages.h"
#include "tests/protocol/samples.h"

namespace {
void roundTrip(const hapticd::proto::Message& m) {
  using namespace hapticd::proto;
  static std::vector<std::uint8_t> buf(kMaxDatagramLimit);
  Errc err = Errc::kOk;
  const std::size_t n = encode({}, m, buf, &err);
  if (n == 0)
    __builtin_trap();  // whatever decodes must encode
  Header h;
  Message back;
  if (decode(std::span(buf.data(), n), h, back).code != Errc::kOk)
    __builtin_trap();
  if (!testing::sameMessage(m, back))
    __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hapticd::proto;
  Header h;
  Message m;
  DecodeError e = decode(std::span(data, size), h, m);
  (void)describe(e);
  if (e.code == Errc::kOk)
    roundTrip(m);
  if (size >= 2) {
    const auto type = static_cast<std::uint16_t>(data[0] % (kMsgTypeEnd + 1));
    e = decodePayload(type, data[1] % 3, std::span(data + 2, size - 2), m);
    (void)describe(e);
    if (e.code == Errc::kOk)
      roundTrip(m);
  }
  return 0;
}
