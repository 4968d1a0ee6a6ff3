#include "io/png_image.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string_view>

#include "io/atomic_file.hpp"

namespace boycott::io {

namespace {

std::uint32_t crc32(const unsigned char* p, std::size_t n, std::uint32_t crc = 0xffffffffu) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xedb88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  for (std::size_t i = 0; i < n; ++i) crc = table[(crc ^ p[i]) & 0xff] ^ (crc >> 8);
  return crc;
}

void put32(std::vector<unsigned char>& o, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) o.push_back(static_cast<unsigned char>(v >> s));
}

void chunk(std::vector<unsigned char>& out, const char* type, const std::vector<unsigned char>& data) {
  put32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  put32(out, crc32(out.data() + start, out.size() - start) ^ 0xffffffffu);
}

}  // namespace

std::vector<unsigned char> encode_png(int w, int h, const std::vector<unsigned char>& rgb) {
  std::vector<unsigned char> raw;  // filter byte 0 + row
  raw.reserve(static_cast<std::size_t>(h) * (3 * w + 1));
  for (int r = 0; r < h; ++r) {
    raw.push_back(0);
    raw.insert(raw.end(), rgb.begin() + static_cast<std::ptrdiff_t>(r) * 3 * w,
               rgb.begin() + static_cast<std::ptrdiff_t>(r + 1) * 3 * w);
  }
  // zlib stream of stored (uncompressed) deflate blocks, Adler-32 at the end.
  std::vector<unsigned char> z = {0x78, 0x01};
  std::size_t pos = 0;
  do {
    const std::size_t len = std::min<std::size_t>(65535, raw.size() - pos);
    const bool last = pos + len == raw.size();
    z.push_back(last ? 1 : 0);
    z.push_back(static_cast<unsigned char>(len & 0xff));
    z.push_back(static_cast<unsigned char>(len >> 8));
    z.push_back(static_cast<unsigned char>(~len & 0xff));
    z.push_back(static_cast<unsigned char>((~len >> 8) & 0xff));
    z.insert(z.end(), raw.begin() + static_cast<std::ptrdiff_t>(pos),
             raw.begin() + static_cast<std::ptrdiff_t>(pos + len));
    pos += len;
  } while (pos < raw.size());
  std::uint32_t a = 1, b = 0;
  for (unsigned char c : raw) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  put32(z, (b << 16) | a);

  std::vector<unsigned char> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<unsigned char> ihdr;
  put32(ihdr, static_cast<std::uint32_t>(w));
  put32(ihdr, static_cast<std::uint32_t>(h));
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8-bit RGB, deflate, no filter, no interlace
  chunk(out, "IHDR", ihdr);
  chunk(out, "IDAT", z);
  chunk(out, "IEND", {});
  return out;
}

void write_particle_png(const std::filesystem::path& path, const ParticleView& v, int max_pixels) {
  const double scale = max_pixels / std::max(v.length_x_m, v.height_z_m);  // px per m
  const int w = std::max(1, static_cast<int>(std::lround(v.length_x_m * scale)));
  const int h = std::max(1, static_cast<int>(std::lround(v.height_z_m * scale)));
  std::vector<unsigned char> img(static_cast<std::size_t>(w) * h * 3, 255);
  for (std::size_t i = 0; i < v.count; ++i) {
    // Wrap into the periodic box, z up.
    double x = std::fmod((*v.x)[i], v.length_x_m), z = std::fmod((*v.z)[i], v.height_z_m);
    if (x < 0) x += v.length_x_m;
    if (z < 0) z += v.height_z_m;
    const double f = std::clamp((*v.y)[i] / v.width_y_m, 0.0, 1.0);
    const unsigned char col[3] = {static_cast<unsigned char>(255 * f), 40,
                                  static_cast<unsigned char>(255 * (1 - f))};
    const double cx = x * scale, cy = (v.height_z_m - z) * scale, rr = std::max(0.7, (*v.radius)[i] * scale);
    for (int py = static_cast<int>(cy - rr); py <= static_cast<int>(cy + rr) + 1; ++py)
      for (int px = static_cast<int>(cx - rr); px <= static_cast<int>(cx + rr) + 1; ++px) {
        const double dx = px + 0.5 - cx, dy = py + 0.5 - cy;
        if (dx * dx + dy * dy > rr * rr) continue;
        const int qx = ((px % w) + w) % w, qy = ((py % h) + h) % h;  // periodic images
        unsigned char* p = &img[(static_cast<std::size_t>(qy) * w + qx) * 3];
        p[0] = col[0], p[1] = col[1], p[2] = col[2];
      }
  }
  const auto bytes = encode_png(w, h, img);
  write_file_atomic(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

}  // namespace boycott::io
