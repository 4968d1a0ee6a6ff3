// The PNG encoder: chunk layout and CRCs (checked bit by bit, independently of the encoder's
// table), the stored-deflate stream holding every scanline, and the Adler-32 of the data.
#include <gtest/gtest.h>

#include <cstdint>

#include "io/png_image.hpp"

namespace {

std::uint32_t be32(const unsigned char* p) {
  return (std::uint32_t(p[0]) << 24) | (p[1] << 16) | (p[2] << 8) | p[3];
}

std::uint32_t crc_bitwise(const unsigned char* p, std::size_t n) {
  std::uint32_t c = 0xffffffffu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return ~c;
}

}  // namespace

TEST(Png, ChunksCarryValidCrcsAndTheStoredStreamHoldsEveryScanline) {
  const int w = 300, h = 250;  // 300 * 3 + 1 = 901 bytes per row: more than one 64 KiB block
  std::vector<unsigned char> rgb(static_cast<std::size_t>(w) * h * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<unsigned char>(i * 7 + 3);
  const auto png = boycott::io::encode_png(w, h, rgb);
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(std::vector<unsigned char>(png.begin(), png.begin() + 8),
            (std::vector<unsigned char>{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'}));
  std::size_t i = 8;
  std::vector<unsigned char> idat;
  std::vector<std::string> types;
  while (i < png.size()) {
    const std::uint32_t n = be32(&png[i]);
    types.emplace_back(png.begin() + i + 4, png.begin() + i + 8);
    EXPECT_EQ(be32(&png[i + 8 + n]), crc_bitwise(&png[i + 4], n + 4)) << types.back();
    if (types.back() == "IHDR") {
      EXPECT_EQ(be32(&png[i + 8]), static_cast<std::uint32_t>(w));
      EXPECT_EQ(be32(&png[i + 12]), static_cast<std::uint32_t>(h));
    }
    if (types.back() == "IDAT") idat.insert(idat.end(), png.begin() + i + 8, png.begin() + i + 8 + n);
    i += 12 + n;
  }
  EXPECT_EQ(types, (std::vector<std::string>{"IHDR", "IDAT", "IEND"}));
  // Inflate the stored blocks by hand.
  std::vector<unsigned char> raw;
  std::size_t p = 2;
  bool last = false;
  while (!last) {
    last = idat[p] & 1;
    const unsigned len = idat[p + 1] | (idat[p + 2] << 8), nlen = idat[p + 3] | (idat[p + 4] << 8);
    ASSERT_EQ(len ^ 0xffffu, nlen);
    raw.insert(raw.end(), idat.begin() + p + 5, idat.begin() + p + 5 + len);
    p += 5 + len;
  }
  ASSERT_EQ(raw.size(), static_cast<std::size_t>(h) * (3 * w + 1));
  for (int r = 0; r < h; ++r) {
    EXPECT_EQ(raw[r * (3 * w + 1)], 0);
    EXPECT_EQ(raw[r * (3 * w + 1) + 1], rgb[static_cast<std::size_t>(r) * 3 * w]);
  }
  std::uint32_t a = 1, b = 0;
  for (unsigned char c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
  EXPECT_EQ(be32(&idat[p]), (b << 16) | a);
}
