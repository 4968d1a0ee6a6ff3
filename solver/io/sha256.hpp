#pragma once
// SHA-256 (FIPS 180-4, "Secure Hash Standard", NIST 2015, sections 4.1.2, 4.2.2, 5.1.1, 6.2),
// written from the standard: the digest that proves a checkpoint file is the one its writer wrote.
// Streaming: update() any number of times, then hex() once.
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
  void block(const std::uint8_t* p);
  std::array<std::uint32_t, 8> h_;
  std::array<std::uint8_t, 64> buf_{};
  std::size_t buf_n_ = 0;
  std::uint64_t total_bytes_ = 0;
};

}  // namespace boycott::io
