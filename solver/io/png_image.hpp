#pragma once
// Pictures of the particles in the x-z plane (paper Figs. 7 and 10), drawn with Cairo and written
// as compressed PNG: each particle a disc coloured by its y position across the channel (blue at
// y = 0, red at y = W), drawn inside the box (positions wrapped along x and z, the periodic axes,
// and discs that cross a side drawn again at the other), with axes in mm, the simulated time and
// a colour key for y.
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
  double time_s = 0.0;  ///< shown above the picture
};

/// Where the box lies in a picture written by write_particle_png: pixel columns [left, right),
/// rows [top, bottom) (row 0 at the top; z points up).
struct PictureBox {
  int left = 0, top = 0, right = 0, bottom = 0;
  int width = 0, height = 0;  ///< of the whole image
};

/// The layout write_particle_png uses: the box `max_pixels` on its longer side, margins around it
/// for the axes, the time and the colour key.
PictureBox particle_picture_layout(const ParticleView& v, int max_pixels = 800);

/// Writes an RGB PNG (box of at most `max_pixels` on its longer side, plus axes and key).
/// StorageError when the file cannot be written.
void write_particle_png(const std::filesystem::path& path, const ParticleView& v, int max_pixels = 800);

}  // namespace boycott::io
