#include "protocol/auth.h"

#include <sodium.h>

#include <algorithm>
#include <cctype>

namespace hapticd::proto {
namespace {
static_assert(crypto_auth_BYTES == kMacSize);
static_assert(crypto_auth_KEYBYTES == sizeof(Key));

void initSodium() {
  static const int init = sodium_init();
  (void)init;
}
}  // namespace

std::optional<Key> parseKeyHex(std::string_view text, std::string* error) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())))
    text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
    text.remove_suffix(1);
  if (text.size() != 64) {
    if (error)
      *error = "key must be 64 hex digits (32 bytes), got " + std::to_string(text.size()) +
               " characters";
    return std::nullopt;
  }
  Key k{};
  for (std::size_t i = 0; i < 32; ++i) {
    int v = 0;
    for (std::size_t j = 0; j < 2; ++j) {
      const char c = text[2 * i + j];
      int d;
      if (c >= '0' && c <= '9')
        d = c - '0';
      else if (c >= 'a' && c <= 'f')
        d = c - 'a' + 10;
      else if (c >= 'A' && c <= 'F')
        d = c - 'A' + 10;
      else {
        if (error)
          *error = "key: character " + std::to_string(2 * i + j + 1) + " is not hex";
        return std::nullopt;
      }
      v = v * 16 + d;
    }
    k[i] = static_cast<std::uint8_t>(v);
  }
  return k;
}

std::string keyToHex(const Key& key) {
  static const char* digits = "0123456789abcdef";
  std::string s;
  for (auto b : key) {
    s += digits[b >> 4];
    s += digits[b & 15];
  }
  return s;
}

Key randomKey() {
  initSodium();
  Key k;
  randombytes_buf(k.data(), k.size());
  return k;
}

std::uint64_t randomU64() {
  initSodium();
  std::uint64_t v = 0;
  while (v == 0)
    randombytes_buf(&v, sizeof v);
  return v;
}

std::size_t encodeDatagram(Header h,
                           const Message& m,
                           const Key* key,
                           std::span<std::uint8_t> out,
                           Errc* error) {
  if (key) {
    initSodium();
    h.flags = static_cast<std::uint16_t>(h.flags | kFlagMac);
    if (out.size() < kMacSize) {
      if (error)
        *error = Errc::kBufferTooSmall;
      return 0;
    }
    const std::size_t n = encode(h, m, out.first(out.size() - kMacSize), error);
    if (n == 0)
      return 0;
    crypto_auth(out.data() + n, out.data(), n, key->data());
    return n + kMacSize;
  }
  h.flags = static_cast<std::uint16_t>(h.flags & ~kFlagMac);
  return encode(h, m, out, error);
}

bool verifyTag(std::span<const std::uint8_t> d, const Key& key) {
  if (d.size() < kHeaderSize + kMacSize)
    return false;
  initSodium();
  const std::size_t n = d.size() - kMacSize;
  return crypto_auth_verify(d.data() + n, d.data(), n, key.data()) == 0;
}

bool ReplayWindow::check(std::uint64_t seq) const {
  if (seq == 0)
    return false;
  if (seq > top_)
    return true;
  if (top_ - seq >= kWindow)
    return false;
  const std::uint64_t bit = seq % kWindow;
  return (bits_[bit / 64] & (1ull << (bit % 64))) == 0;
}

void ReplayWindow::accept(std::uint64_t seq) {
  if (seq > top_) {
    // clear the bits of the numbers the window moves past (top_+1 .. seq)
    const std::uint64_t step = seq - top_;
    if (step >= kWindow) {
      bits_.fill(0);
    } else {
      for (std::uint64_t s = top_ + 1; s <= seq; ++s) {
        const std::uint64_t bit = s % kWindow;
        bits_[bit / 64] &= ~(1ull << (bit % 64));
      }
    }
    top_ = seq;
  }
  const std::uint64_t bit = seq % kWindow;
  bits_[bit / 64] |= 1ull << (bit % 64);
}

bool TokenBucket::take(std::uint64_t now_ns) {
  if (config_.packets_per_s <= 0.0)
    return true;
  if (now_ns > last_ns_) {
    tokens_ = std::min(config_.burst, tokens_ + static_cast<double>(now_ns - last_ns_) * 1e-9 *
                                                    config_.packets_per_s);
    last_ns_ = now_ns;
  }
  if (tokens_ < 1.0)
    return false;
  tokens_ -= 1.0;
  return true;
}

}  // namespace hapticd::proto
