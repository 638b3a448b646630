#pragma once
/// \file
/// Whether this build runs under AddressSanitizer (GCC defines __SANITIZE_ADDRESS__, clang answers
/// __has_feature(address_sanitizer)): what a sanitized build cannot do (lock all memory, limit its
/// address space: the shadow memory alone is terabytes) or does too slowly (the longest runs).

namespace hapticd {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif

}  // namespace hapticd
