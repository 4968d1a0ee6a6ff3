#pragma once
// Pictures of the particles in the x-z plane (paper Figs. 7 and 10): a PNG written without a
// compression library (stored deflate blocks), each particle a disc coloured by its y position
// across the channel (blue at y = 0, red at y = W).
#include <filesystem>
#include <vector>

namespace boycott::io {

struct ParticleView {
  const std::vector<double>* x = nullptr;  ///< m
  const std::vector<double>* y = nullptr;  ///< m, colour
  const std::vector<double>* z = nullptr;  ///< m
  const std::vector<double>* radius = nullptr;
  std::size_t count = 0;
  double length_x_m = 1.0, width_y_m = 1.0, height_z_m = 1.0;
};

/// Writes an RGB PNG of at most `max_pixels` on its longer side; z points up.
void write_particle_png(const std::filesystem::path& path, const ParticleView& v, int max_pixels = 800);

/// Encodes an 8-bit RGB image (rows top to bottom, 3 bytes per pixel) as PNG bytes.
std::vector<unsigned char> encode_png(int width, int height, const std::vector<unsigned char>& rgb);

}  // namespace boycott::io
