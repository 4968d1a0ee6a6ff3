#pragma once
// Plots drawn with Cairo (Debian libcairo2-dev) and written as SVG, PDF or PNG: the canvas the query
// plots (curve, work-precision) draw on, with their shared pieces (lines, text, markers, axes).
// Each drawn element is also tallied by its kind, and each text kept, so that tests can check
// what a plot holds without reading the vector output.
#include <functional>
#include <map>
#include <string>
#include <vector>

typedef struct _cairo cairo_t;  // NOLINT: the same declaration as <cairo.h>

namespace boycott::driver::plot {

enum class Format { kSvg, kPdf, kPng };
/// PDF for a path ending in ".pdf", PNG for ".png" (any case), SVG otherwise.
Format format_of_path(const std::string& path);

/// A finished plot: the file's bytes, and what was drawn.
struct Plot {
  std::string data;
  std::map<std::string, int> drawn;  // kind of element ("panel", "group", ...) -> count
  std::vector<std::string> texts;    // every text, in drawing order
  int count(const std::string& kind) const;
  bool has_text(const std::string& s) const;
};

enum class Anchor { kStart, kMiddle, kEnd };

/// A Cairo context with the plots' conventions: y down, units of 1/96 inch (CSS pixels in the
/// SVG), colours as "#rgb" or "#rrggbb".
class Canvas {
 public:
  explicit Canvas(cairo_t* cr, Plot& plot) : cr_(cr), plot_(plot) {}
  cairo_t* cr() const { return cr_; }
  /// Counts one element of `kind` (nothing when empty).
  void tally(const std::string& kind);

  void fill_rect(double x, double y, double w, double h, const char* color);
  void stroke_rect(double x, double y, double w, double h, const char* color, const std::string& kind = "");
  /// A line; `dash` like SVG's stroke-dasharray ({} for solid).
  void line(double x1, double y1, double x2, double y2, const char* color, double width = 1.0,
            const std::vector<double>& dash = {}, const std::string& kind = "");
  void polyline(const std::vector<std::pair<double, double>>& pts, const char* color, double width,
                const std::string& kind = "");
  void circle(double x, double y, double r, const char* color, double alpha = 1.0,
              const std::string& kind = "");
  /// A marker centred on (x, y): circle, square, diamond or triangle; hollow: white inside with a
  /// coloured outline (points not drawn where their value is, e.g. clamped to a log axis floor).
  void marker(const char* kind, double x, double y, const char* color, bool hollow = false);
  /// Text with its baseline at y; rotated: read bottom to top, anchored around (x, y).
  void text(double x, double y, const std::string& s, Anchor anchor = Anchor::kStart, double size = 13.0,
            const char* color = "#000", bool rotated = false, const std::string& kind = "");
  /// A label the program composes, typeset: "_{...}" is drawn as a subscript ("⟨⟨w_{p}⟩⟩",
  /// "r_{acc}"); recorded in texts without the markup. User text (names) goes through text().
  void label(double x, double y, const std::string& s, Anchor anchor = Anchor::kStart, double size = 13.0,
             bool rotated = false);
  /// The advance of `s` at `size` (px), for laying out a row of legend entries.
  double text_width(const std::string& s, double size = 13.0);
  /// Restricts drawing to a rectangle until unclip().
  void clip(double x, double y, double w, double h);
  void unclip();

 private:
  void source(const char* color, double alpha = 1.0);
  cairo_t* cr_;
  Plot& plot_;
};

/// The advance of `s` at `size` (px) in the plots' font, measured before any canvas exists (to
/// size a plot by its text); within a few tenths of a pixel of Canvas::text_width.
double text_width(const std::string& s, double size = 13.0);

/// Draws a width x height plot on a white page through `draw` and writes it in `format`.
Plot render(double width, double height, Format format, const std::function<void(Canvas&)>& draw);

}  // namespace boycott::driver::plot
