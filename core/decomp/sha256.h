#pragma once
/// \file
/// SHA-256 (FIPS 180-4, §6.2) for content hashes (cache keys). core/ may not use libsodium (the
/// protocol's), so this is a plain implementation of the standard. Any thread.

#include <array>
#include <cstdint>
#include <span>
#include <string>

namespace hapticd::decomp {

class Sha256 {
 public:
  Sha256();
  void update(std::span<const std::uint8_t> bytes);
  void update(const void* data, std::size_t size);
  /// The digest as 64 lowercase hex digits. Finishes the hash (call once).
  std::string hexDigest();

 private:
  void block(const std::uint8_t* p);
  std::array<std::uint32_t, 8> h_;
  std::array<std::uint8_t, 64> buf_{};
  std::size_t used_ = 0;
  std::uint64_t total_ = 0;
};

}  // namespace hapticd::decomp
