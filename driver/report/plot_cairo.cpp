#include "driver/report/plot_cairo.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>
#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott::driver::plot {

Format format_of_path(const std::string& path) {
  std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : "";
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".pdf") return Format::kPdf;
  if (ext == ".png") return Format::kPng;
  if (ext == ".svg") return Format::kSvg;
  // Another extension would get a file whose content is not what its name says.
  throw InputError(
      fmt::format("--plot {}: the plot's format comes from its extension, which must be .svg, "
                  ".png or .pdf",
                  path));
}

int Plot::count(const std::string& kind) const {
  const auto it = drawn.find(kind);
  return it == drawn.end() ? 0 : it->second;
}

bool Plot::has_text(const std::string& s) const {
  return std::find(texts.begin(), texts.end(), s) != texts.end();
}

void Canvas::tally(const std::string& kind) {
  if (!kind.empty()) ++plot_.drawn[kind];
}

void Canvas::source(const char* color, double alpha) {
  // "#rgb" or "#rrggbb".
  const std::string c = color[0] == '#' ? color + 1 : color;
  auto hex = [&](std::size_t at, std::size_t n) {
    const double v = std::stoi(c.substr(at, n), nullptr, 16);
    return n == 1 ? v / 15.0 : v / 255.0;
  };
  const std::size_t n = c.size() == 3 ? 1 : 2;
  if (c.size() != 3 && c.size() != 6)
    throw std::logic_error(fmt::format("colour '{}' is not #rgb or #rrggbb", color));
  cairo_set_source_rgba(cr_, hex(0, n), hex(n, n), hex(2 * n, n), alpha);
}

void Canvas::fill_rect(double x, double y, double w, double h, const char* color) {
  source(color);
  cairo_rectangle(cr_, x, y, w, h);
  cairo_fill(cr_);
}

void Canvas::stroke_rect(double x, double y, double w, double h, const char* color, const std::string& kind) {
  source(color);
  cairo_set_line_width(cr_, 1.0);
  cairo_set_dash(cr_, nullptr, 0, 0);
  cairo_rectangle(cr_, x, y, w, h);
  cairo_stroke(cr_);
  tally(kind);
}

void Canvas::line(double x1, double y1, double x2, double y2, const char* color, double width,
                  const std::vector<double>& dash, const std::string& kind) {
  source(color);
  cairo_set_line_width(cr_, width);
  cairo_set_dash(cr_, dash.data(), static_cast<int>(dash.size()), 0);
  cairo_move_to(cr_, x1, y1);
  cairo_line_to(cr_, x2, y2);
  cairo_stroke(cr_);
  cairo_set_dash(cr_, nullptr, 0, 0);
  tally(kind);
}

void Canvas::polyline(const std::vector<std::pair<double, double>>& pts, const char* color, double width,
                      const std::string& kind) {
  if (pts.empty()) return;
  source(color);
  cairo_set_line_width(cr_, width);
  cairo_set_dash(cr_, nullptr, 0, 0);
  cairo_set_line_join(cr_, CAIRO_LINE_JOIN_ROUND);
  cairo_move_to(cr_, pts[0].first, pts[0].second);
  for (std::size_t i = 1; i < pts.size(); ++i) cairo_line_to(cr_, pts[i].first, pts[i].second);
  cairo_stroke(cr_);
  tally(kind);
}

void Canvas::circle(double x, double y, double r, const char* color, double alpha, const std::string& kind) {
  source(color, alpha);
  cairo_new_sub_path(cr_);
  cairo_arc(cr_, x, y, r, 0, 2 * std::numbers::pi);
  cairo_fill(cr_);
  tally(kind);
}

void Canvas::marker(const char* kind, double x, double y, const char* color, bool hollow) {
  const std::string k = kind;
  cairo_new_path(cr_);
  if (k == "circle") {
    cairo_arc(cr_, x, y, 4, 0, 2 * std::numbers::pi);
  } else if (k == "square") {
    cairo_rectangle(cr_, x - 4, y - 4, 8, 8);
  } else if (k == "diamond") {
    cairo_move_to(cr_, x, y - 5), cairo_line_to(cr_, x + 5, y), cairo_line_to(cr_, x, y + 5);
    cairo_line_to(cr_, x - 5, y), cairo_close_path(cr_);
  } else {
    cairo_move_to(cr_, x, y - 5), cairo_line_to(cr_, x + 5, y + 4), cairo_line_to(cr_, x - 5, y + 4);
    cairo_close_path(cr_);
  }
  if (hollow) {
    source("#fff");
    cairo_fill_preserve(cr_);
    source(color);
    cairo_set_line_width(cr_, 1.5);
    cairo_set_dash(cr_, nullptr, 0, 0);
    cairo_stroke(cr_);
    tally("hollow marker");
  } else {
    source(color);
    cairo_fill(cr_);
    tally("marker");
  }
}

void Canvas::text(double x, double y, const std::string& s, Anchor anchor, double size, const char* color,
                  bool rotated, const std::string& kind) {
  cairo_save(cr_);
  cairo_select_font_face(cr_, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr_, size);
  source(color);
  cairo_text_extents_t e;
  cairo_text_extents(cr_, s.c_str(), &e);
  const double shift = anchor == Anchor::kStart    ? 0.0
                       : anchor == Anchor::kMiddle ? e.x_advance / 2
                                                   : e.x_advance;
  cairo_translate(cr_, x, y);
  if (rotated) cairo_rotate(cr_, -std::numbers::pi / 2);
  cairo_move_to(cr_, -shift, 0);
  cairo_show_text(cr_, s.c_str());
  cairo_restore(cr_);
  plot_.texts.push_back(s);
  tally(kind);
}

void Canvas::label(double x, double y, const std::string& s, Anchor anchor, double size, bool rotated) {
  // Runs of normal and subscript text: "_{" opens a subscript, "}" closes it.
  struct Run {
    std::string text;
    bool sub;
  };
  std::vector<Run> runs;
  std::string plain;
  for (std::size_t i = 0; i < s.size();) {
    const bool sub = s.compare(i, 2, "_{") == 0;
    const std::size_t from = sub ? i + 2 : i;
    const std::size_t to = sub ? s.find('}', from) : s.find("_{", from);
    const std::size_t end = to == std::string::npos ? s.size() : to;
    runs.push_back({s.substr(from, end - from), sub});
    plain += runs.back().text;
    i = sub && to != std::string::npos ? end + 1 : end;
  }
  const double sub_size = 0.72 * size, drop = 0.28 * size;
  cairo_save(cr_);
  cairo_select_font_face(cr_, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  source("#000");
  double width = 0.0;
  for (const auto& r : runs) {
    cairo_set_font_size(cr_, r.sub ? sub_size : size);
    cairo_text_extents_t e;
    cairo_text_extents(cr_, r.text.c_str(), &e);
    width += e.x_advance;
  }
  const double shift = anchor == Anchor::kStart ? 0.0 : anchor == Anchor::kMiddle ? width / 2 : width;
  cairo_translate(cr_, x, y);
  if (rotated) cairo_rotate(cr_, -std::numbers::pi / 2);
  double at = -shift;
  for (const auto& r : runs) {
    cairo_set_font_size(cr_, r.sub ? sub_size : size);
    cairo_move_to(cr_, at, r.sub ? drop : 0.0);
    cairo_show_text(cr_, r.text.c_str());
    cairo_text_extents_t e;
    cairo_text_extents(cr_, r.text.c_str(), &e);
    at += e.x_advance;
  }
  cairo_restore(cr_);
  plot_.texts.push_back(plain);
}

double Canvas::text_width(const std::string& s, double size) {
  cairo_save(cr_);
  cairo_select_font_face(cr_, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr_, size);
  cairo_text_extents_t e;
  cairo_text_extents(cr_, s.c_str(), &e);
  cairo_restore(cr_);
  return e.x_advance;
}

void Canvas::clip(double x, double y, double w, double h) {
  cairo_save(cr_);
  cairo_rectangle(cr_, x, y, w, h);
  cairo_clip(cr_);
}

void Canvas::unclip() {
  cairo_restore(cr_);
}

namespace {

cairo_status_t append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

double text_width(const std::string& s, double size) {
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, 1, 1);
  cairo_t* cr = cairo_create(surface);
  Plot scratch;
  const double w = Canvas(cr, scratch).text_width(s, size);
  cairo_destroy(cr);
  cairo_surface_destroy(surface);
  return w;
}

Plot render(double width, double height, Format format, const std::function<void(Canvas&)>& draw) {
  Plot plot;
  cairo_surface_t* surface = nullptr;
  if (format == Format::kPdf) {
    // PDF pages are measured in points (1/72 inch); the plots are laid out in 1/96 inch.
    surface = cairo_pdf_surface_create_for_stream(append, &plot.data, width * 0.75, height * 0.75);
  } else if (format == Format::kPng) {
    surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, static_cast<int>(std::ceil(width)),
                                         static_cast<int>(std::ceil(height)));
  } else {
    surface = cairo_svg_surface_create_for_stream(append, &plot.data, width, height);
    cairo_svg_surface_set_document_unit(surface, CAIRO_SVG_UNIT_PX);
  }
  cairo_t* cr = cairo_create(surface);
  if (format == Format::kPdf) cairo_scale(cr, 0.75, 0.75);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  Canvas canvas(cr, plot);
  canvas.fill_rect(0, 0, width, height, "#fff");
  std::string error;
  try {
    draw(canvas);
  } catch (...) {
    cairo_destroy(cr);
    cairo_surface_destroy(surface);
    throw;
  }
  if (cairo_status(cr) != CAIRO_STATUS_SUCCESS) error = cairo_status_to_string(cairo_status(cr));
  cairo_destroy(cr);
  if (format == Format::kPng && error.empty()) {
    const cairo_status_t st = cairo_surface_write_to_png_stream(surface, append, &plot.data);
    if (st != CAIRO_STATUS_SUCCESS) error = cairo_status_to_string(st);
  }
  cairo_surface_finish(surface);  // writes the rest of the file
  if (error.empty() && cairo_surface_status(surface) != CAIRO_STATUS_SUCCESS)
    error = cairo_status_to_string(cairo_surface_status(surface));
  cairo_surface_destroy(surface);
  if (!error.empty()) throw std::runtime_error(fmt::format("drawing the plot failed: {}", error));
  return plot;
}

}  // namespace boycott::driver::plot
