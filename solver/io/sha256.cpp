#include "io/sha256.hpp"

namespace boycott::io {

Sha256::Sha256() {
  sha256_init(&ctx_);
}

void Sha256::update(const void* data, std::size_t n) {
  sha256_update(&ctx_, n, static_cast<const std::uint8_t*>(data));
}

std::array<std::uint8_t, 32> Sha256::digest() {
  std::array<std::uint8_t, 32> out{};
  static_assert(SHA256_DIGEST_SIZE == 32);
  sha256_digest(&ctx_, out.size(), out.data());
  return out;
}

std::string Sha256::hex() {
  static const char* digits = "0123456789abcdef";
  std::string s;
  for (const std::uint8_t b : digest()) {
    s += digits[b >> 4];
    s += digits[b & 15];
  }
  return s;
}

}  // namespace boycott::io
