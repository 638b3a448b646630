// libFuzzer target: the header decoder. Any input: no crash, and a header that decodes
// re-encodes to the same 40 bytes (except the reserved field, which is ignored).
#include <cstdint>
#include <cstring>
#include <span>

#include "protocol/wire.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hapticd::proto;
  Header h;
  const DecodeError e = decodeHeader(std::span(data, size), h);
  (void)describe(e);
  if (e.code == Errc::kOk) {
    std::uint8_t out[kHeaderSize];
    encodeHeader(h, out);
    // bytes 10..11 are reserved (ignored on receive, zero on send)
    if (std::memcmp(out, data, 10) != 0 || std::memcmp(out + 12, data + 12, kHeaderSize - 12) != 0)
      __builtin_trap();
    if (size != kHeaderSize + h.payload_length + ((h.flags & kFlagMac) ? kMacSize : 0))
      __builtin_trap();
  }
  return 0;
}
