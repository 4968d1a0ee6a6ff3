// Particle pictures drawn with Cairo: a valid, compressed PNG of the layout's size, particles
// inside the box (one just past the periodic side drawn at the other side, nothing beyond the
// box), and a colour key running from blue (y = 0) to red (y = W).
#include <gtest/gtest.h>

#include <cairo.h>

#include <cstdint>
#include <filesystem>
#include <random>

#include "io/png_image.hpp"

namespace {

namespace fs = std::filesystem;

struct Rgb {
  int r, g, b;
};

struct Image {
  cairo_surface_t* s = nullptr;
  explicit Image(const fs::path& p) : s(cairo_image_surface_create_from_png(p.c_str())) {}
  ~Image() { cairo_surface_destroy(s); }
  bool ok() const { return cairo_surface_status(s) == CAIRO_STATUS_SUCCESS; }
  int width() const { return cairo_image_surface_get_width(s); }
  int height() const { return cairo_image_surface_get_height(s); }
  Rgb at(int x, int y) const {
    const auto* row =
        cairo_image_surface_get_data(s) + static_cast<std::ptrdiff_t>(y) * cairo_image_surface_get_stride(s);
    const std::uint32_t px = reinterpret_cast<const std::uint32_t*>(row)[x];
    return {static_cast<int>((px >> 16) & 0xff), static_cast<int>((px >> 8) & 0xff),
            static_cast<int>(px & 0xff)};
  }
};

bool reddish(Rgb c) {
  return c.r > 200 && c.b < 60;
}
bool bluish(Rgb c) {
  return c.b > 200 && c.r < 60;
}

}  // namespace

TEST(ParticlePng, ValidCompressedAndOfTheLayoutsSize) {
  std::vector<double> x, y, z, r;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    x.push_back(0.02 * u(rng)), y.push_back(0.006 * u(rng)), z.push_back(0.02 * u(rng)), r.push_back(1.5e-4);
  }
  const boycott::io::ParticleView v{&x, &y, &z, &r, x.size(), 0.02, 0.006, 0.02, 1.25};
  const fs::path p = fs::temp_directory_path() / "boycott_test_particles.png";
  boycott::io::write_particle_png(p, v);
  const auto layout = boycott::io::particle_picture_layout(v);
  Image img(p);
  ASSERT_TRUE(img.ok());
  EXPECT_EQ(img.width(), layout.width);
  EXPECT_EQ(img.height(), layout.height);
  EXPECT_EQ(layout.right - layout.left, 800);
  // Compressed: far below the raw 3 bytes per pixel (the stored deflate blocks of the former
  // hand-written encoder were slightly above it); 2000 discs of random colour: about raw / 6.
  const auto raw = static_cast<std::uintmax_t>(layout.width) * layout.height * 3;
  EXPECT_LT(fs::file_size(p), raw / 4) << fs::file_size(p) << " bytes for " << raw << " raw";
}

TEST(ParticlePng, ParticleJustPastThePeriodicSideIsDrawnInsideTheBox) {
  const double L = 0.02, W = 0.006, H = 0.02;
  // One red particle (y = W), radius 0.5 mm, at x = L + 4 um: its centre wraps to x = 4 um.
  std::vector<double> x{L + 4e-6}, y{W}, z{0.37 * H}, r{5e-4};
  const boycott::io::ParticleView v{&x, &y, &z, &r, 1, L, W, H, 0.0};
  const fs::path p = fs::temp_directory_path() / "boycott_test_wrap.png";
  boycott::io::write_particle_png(p, v, 400);
  const auto b = boycott::io::particle_picture_layout(v, 400);
  Image img(p);
  ASSERT_TRUE(img.ok());
  const double px_per_m = (b.right - b.left) / L;
  const int row = static_cast<int>(b.bottom - 0.37 * H * px_per_m);
  // Inside the box on both sides (the disc crosses x = 0, so its periodic image shows at x = L).
  EXPECT_TRUE(reddish(img.at(b.left + 3, row)));
  EXPECT_TRUE(reddish(img.at(b.right - 4, row)));
  // Nothing red outside the box, beside it on either side.
  for (int dx = 2; dx < 10; ++dx) {
    EXPECT_FALSE(reddish(img.at(b.right + dx, row))) << dx;
    EXPECT_FALSE(reddish(img.at(b.left - dx, row))) << dx;
  }
  // The colour key, right of the box: red at the top (y = W), blue at the bottom (y = 0).
  int red_rows = 0, blue_rows = 0, first_red = -1, last_blue = -1;
  for (int yy = b.top; yy < b.bottom; ++yy)
    for (int xx = b.right + 10; xx < b.width; ++xx) {
      const Rgb c = img.at(xx, yy);
      if (reddish(c)) {
        if (first_red < 0) first_red = yy;
        ++red_rows;
        break;
      }
      if (bluish(c)) {
        last_blue = yy;
        ++blue_rows;
        break;
      }
    }
  EXPECT_GT(red_rows, 5);
  EXPECT_GT(blue_rows, 5);
  EXPECT_LT(first_red, last_blue);
}
