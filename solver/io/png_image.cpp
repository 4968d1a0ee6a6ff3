#include "io/png_image.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/snapshot.hpp"

namespace boycott::io {

namespace {

constexpr int kLeft = 70, kTop = 36, kBottom = 56, kKey = 110;  // margins, px

/// Tick spacing of about `target` intervals over `span`: 1, 2 or 5 times a power of ten.
double nice_step(double span, int target) {
  const double raw = span / target, p = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0})
    if (m * p >= raw) return m * p;
  return 10.0 * p;
}

std::string tick_label(double v, double step) {
  const int digits = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  return fmt::format("{:.{}f}", v, digits);
}

void text(cairo_t* cr, const std::string& s, double x, double y, double ax, double ay) {
  cairo_text_extents_t e;
  cairo_text_extents(cr, s.c_str(), &e);
  cairo_move_to(cr, x - ax * e.width - e.x_bearing, y - ay * e.height - e.y_bearing);
  cairo_show_text(cr, s.c_str());
}

void colour(cairo_t* cr, double f) {
  cairo_set_source_rgb(cr, f, 40.0 / 255.0, 1.0 - f);
}

/// Ticks and labels (in mm) along one side of the box.
void axis(cairo_t* cr, const PictureBox& b, double length_m, bool horizontal) {
  const double mm = length_m * 1e3, step = nice_step(mm, 5);
  const double px = horizontal ? b.right - b.left : b.bottom - b.top;
  for (double v = 0.0; v <= mm * (1 + 1e-9); v += step) {
    const double p = v / mm * px;
    cairo_set_source_rgb(cr, 0, 0, 0);
    if (horizontal) {
      cairo_move_to(cr, b.left + p, b.bottom);
      cairo_line_to(cr, b.left + p, b.bottom + 6);
      cairo_stroke(cr);
      text(cr, tick_label(v, step), b.left + p, b.bottom + 9, 0.5, 0.0);
    } else {
      cairo_move_to(cr, b.left, b.bottom - p);
      cairo_line_to(cr, b.left - 6, b.bottom - p);
      cairo_stroke(cr);
      text(cr, tick_label(v, step), b.left - 9, b.bottom - p, 1.0, 0.5);
    }
  }
}

cairo_status_t append(void* out, const unsigned char* data, unsigned int n) {
  static_cast<std::string*>(out)->append(reinterpret_cast<const char*>(data), n);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

PictureBox particle_picture_layout(const ParticleView& v, int max_pixels) {
  const double scale = max_pixels / std::max(v.length_x_m, v.height_z_m);  // px per m
  PictureBox b;
  const int w = std::max(1, static_cast<int>(std::lround(v.length_x_m * scale)));
  const int h = std::max(1, static_cast<int>(std::lround(v.height_z_m * scale)));
  b.left = kLeft, b.top = kTop, b.right = kLeft + w, b.bottom = kTop + h;
  b.width = b.right + kKey, b.height = b.bottom + kBottom;
  return b;
}

void write_particle_png(const std::filesystem::path& path, const ParticleView& v, int max_pixels) {
  const PictureBox b = particle_picture_layout(v, max_pixels);
  const double sx = (b.right - b.left) / v.length_x_m, sz = (b.bottom - b.top) / v.height_z_m;
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, b.width, b.height);
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 13);

  // Particles, clipped to the box; a disc that crosses a side is drawn again at the other.
  cairo_save(cr);
  cairo_rectangle(cr, b.left, b.top, b.right - b.left, b.bottom - b.top);
  cairo_clip(cr);
  for (std::size_t i = 0; i < v.count; ++i) {
    const double x = wrap_into_box((*v.x)[i], v.length_x_m), z = wrap_into_box((*v.z)[i], v.height_z_m);
    const double r = (*v.radius)[i];
    colour(cr, std::clamp((*v.y)[i] / v.width_y_m, 0.0, 1.0));
    for (int ix = -1; ix <= 1; ++ix)
      for (int iz = -1; iz <= 1; ++iz) {
        const double cx = x + ix * v.length_x_m, cz = z + iz * v.height_z_m;
        if (cx + r < 0 || cx - r > v.length_x_m || cz + r < 0 || cz - r > v.height_z_m) continue;
        cairo_new_sub_path(cr);
        cairo_arc(cr, b.left + cx * sx, b.bottom - cz * sz, std::max(0.7, r * sx), 0, 2 * M_PI);
      }
    cairo_fill(cr);
  }
  cairo_restore(cr);

  // Box, axes in mm, the time.
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1.0);
  cairo_rectangle(cr, b.left - 0.5, b.top - 0.5, b.right - b.left + 1, b.bottom - b.top + 1);
  cairo_stroke(cr);
  axis(cr, b, v.length_x_m, true);
  axis(cr, b, v.height_z_m, false);
  text(cr, "x [mm]", 0.5 * (b.left + b.right), b.height - 6, 0.5, 1.0);
  cairo_save(cr);
  cairo_translate(cr, 14, 0.5 * (b.top + b.bottom));
  cairo_rotate(cr, -M_PI / 2);
  text(cr, "z [mm]", 0, 0, 0.5, 0.5);
  cairo_restore(cr);
  text(cr, fmt::format("t = {:.3f} s   ({} particles)", v.time_s, v.count), b.left, b.top - 10, 0.0, 1.0);

  // Colour key: y across the channel, 0 to W.
  const double kx = b.right + 24, kw = 16, ktop = b.top + 10, kbot = b.bottom - 10;
  cairo_pattern_t* grad = cairo_pattern_create_linear(0, kbot, 0, ktop);
  cairo_pattern_add_color_stop_rgb(grad, 0.0, 0.0, 40.0 / 255.0, 1.0);
  cairo_pattern_add_color_stop_rgb(grad, 1.0, 1.0, 40.0 / 255.0, 0.0);
  cairo_rectangle(cr, kx, ktop, kw, kbot - ktop);
  cairo_set_source(cr, grad);
  cairo_fill_preserve(cr);
  cairo_pattern_destroy(grad);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_stroke(cr);
  const double wmm = v.width_y_m * 1e3;
  text(cr, "0", kx + kw + 5, kbot, 0.0, 0.5);
  text(cr, tick_label(wmm, nice_step(wmm, 5)), kx + kw + 5, ktop, 0.0, 0.5);
  text(cr, "y [mm]", kx + 0.5 * kw, ktop - 6, 0.5, 1.0);

  cairo_destroy(cr);
  cairo_surface_flush(surface);
  std::string bytes;
  const cairo_status_t st = cairo_surface_write_to_png_stream(surface, append, &bytes);
  cairo_surface_destroy(surface);
  if (st != CAIRO_STATUS_SUCCESS)
    throw StorageError(fmt::format("cannot encode {}: {}", path.string(), cairo_status_to_string(st)));
  write_file_atomic(path, std::string_view(bytes));
}

}  // namespace boycott::io
