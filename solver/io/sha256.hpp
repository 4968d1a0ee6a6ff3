#pragma once
// SHA-256 (FIPS 180-4), the digest that proves a checkpoint file is the one its writer wrote,
// computed by nettle (Debian nettle-dev). Streaming: update() any number of times, then hex() once.
#include <nettle/sha2.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace boycott::io {

class Sha256 {
 public:
  Sha256();
  void update(const void* data, std::size_t n);
  /// The 32-byte digest; the object is used up afterwards.
  std::array<std::uint8_t, 32> digest();
  /// The digest as 64 lower-case hex digits.
  std::string hex();

 private:
  sha256_ctx ctx_;
};

}  // namespace boycott::io
