#pragma once
#include <cstdint>
#include <string>
#include <string_view>

namespace boycott {

/// 64-bit FNV-1a. Used for case identities (over the canonical parameter JSON) and
/// checkpoint consistency, not for security.
constexpr std::uint64_t fnv1a64(std::string_view s, std::uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

/// 16 hex digits.
std::string hex64(std::uint64_t v);

}  // namespace boycott
