#include "stats/peak_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "stats/distributions.hpp"

namespace boycott::stats {
namespace {

/// SplitMix64 (Steele, Lea & Flood 2014) and Box-Muller: the same draws from the same seed
/// everywhere (the standard library's normal_distribution is not specified bit for bit).
class NormalDraws {
 public:
  explicit NormalDraws(std::uint64_t seed) : state_(seed) {}
  double next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = uniform_open(), u2 = uniform_open();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * std::numbers::pi * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  std::uint64_t bits() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  /// In (0, 1): the top 53 bits, offset by half a step.
  double uniform_open() { return (static_cast<double>(bits() >> 11) + 0.5) * 0x1.0p-53; }
  std::uint64_t state_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

struct Vertex {
  double x = 0.0, y = 0.0;
};

std::size_t argmax(const std::vector<double>& y) {
  return static_cast<std::size_t>(std::max_element(y.begin(), y.end()) - y.begin());
}

/// `width` consecutive indices around `top` (fewer where there are fewer points), shifted inward
/// at the ends: [first, last].
std::pair<std::size_t, std::size_t> window_around(std::size_t top, std::size_t n, std::size_t width) {
  width = std::min(width, n);
  const std::size_t half = width / 2;
  std::size_t first = top >= half ? top - half : 0;
  first = std::min(first, n - width);
  return {first, first + width - 1};
}

/// The weighted least-squares quadratic a + b u + c u^2 in u = (x - x0) / scale through points
/// [first, last] (values `y`, weights 1/error^2), with the variance of c.
struct Quadratic {
  double x0 = 0.0, scale = 1.0;
  double a = 0.0, b = 0.0, c = 0.0;
  double var_c = 0.0;
  double at(double x) const {
    const double u = (x - x0) / scale;
    return a + b * u + c * u * u;
  }
};

/// Solves the 3x3 system m x = r by elimination with partial pivoting; false when singular.
bool solve3(std::array<std::array<double, 3>, 3> m, std::array<double, 3> r, std::array<double, 3>& x) {
  for (int col = 0; col < 3; ++col) {
    int piv = col;
    for (int i = col + 1; i < 3; ++i)
      if (std::abs(m[i][col]) > std::abs(m[piv][col])) piv = i;
    std::swap(m[col], m[piv]);
    std::swap(r[col], r[piv]);
    if (m[col][col] == 0.0) return false;
    for (int i = col + 1; i < 3; ++i) {
      const double f = m[i][col] / m[col][col];
      for (int k = col; k < 3; ++k) m[i][k] -= f * m[col][k];
      r[i] -= f * r[col];
    }
  }
  for (int i = 2; i >= 0; --i) {
    double s = r[i];
    for (int k = i + 1; k < 3; ++k) s -= m[i][k] * x[k];
    x[i] = s / m[i][i];
  }
  return true;
}

Quadratic fit_quadratic(const std::vector<PeakPoint>& p, const std::vector<double>& y, std::size_t first,
                        std::size_t last, std::size_t top) {
  Quadratic q;
  q.x0 = p[top].x;
  q.scale = std::max(p[last].x - p[first].x, 1e-300);
  std::array<double, 5> su{};  // sums of w u^k
  std::array<double, 3> sy{};  // sums of w u^k y
  for (std::size_t i = first; i <= last; ++i) {
    const double u = (p[i].x - q.x0) / q.scale, w = 1.0 / (p[i].error * p[i].error);
    double uk = w;
    for (std::size_t k = 0; k < 5; ++k) {
      su[k] += uk;
      if (k < 3) sy[k] += uk * y[i];
      uk *= u;
    }
  }
  const std::array<std::array<double, 3>, 3> m = {
      {{su[0], su[1], su[2]}, {su[1], su[2], su[3]}, {su[2], su[3], su[4]}}};
  std::array<double, 3> coef{}, unit_c{};
  if (!solve3(m, sy, coef) || !solve3(m, {0.0, 0.0, 1.0}, unit_c)) {
    q.a = y[top];
    q.var_c = std::numeric_limits<double>::infinity();
    return q;
  }
  q.a = coef[0];
  q.b = coef[1];
  q.c = coef[2];
  q.var_c = unit_c[2];  // (X^T W X)^-1 at c, c: errors as standard deviations
  return q;
}

/// The vertex of the quadratic through points [first, last], kept within their span; one that
/// opens upward, or a line through two points, peaks at an end.
Vertex window_vertex(const std::vector<PeakPoint>& p, const std::vector<double>& y, std::size_t first,
                     std::size_t last, std::size_t top) {
  if (first == last) return {p[top].x, y[top]};
  if (last == first + 1)
    return y[first] >= y[last] ? Vertex{p[first].x, y[first]} : Vertex{p[last].x, y[last]};
  const Quadratic q = fit_quadratic(p, y, first, last, top);
  double x = 0.0;
  if (q.c < 0.0)
    x = std::clamp(q.x0 - q.b * q.scale / (2.0 * q.c), p[first].x, p[last].x);
  else
    x = q.at(p[first].x) >= q.at(p[last].x) ? p[first].x : p[last].x;
  return {x, q.at(x)};
}

/// The vertex of the quadratic through the `width` points around the highest of `y`.
Vertex top_vertex(const std::vector<PeakPoint>& p, const std::vector<double>& y, std::size_t width) {
  const std::size_t top = argmax(y);
  const auto [first, last] = window_around(top, p.size(), width);
  return window_vertex(p, y, first, last, top);
}

/// The p-quantile of sorted values (linear between order statistics).
double quantile(const std::vector<double>& sorted, double q) {
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const auto i = static_cast<std::size_t>(pos);
  if (i + 1 >= sorted.size()) return sorted.back();
  return sorted[i] + (pos - static_cast<double>(i)) * (sorted[i + 1] - sorted[i]);
}

constexpr std::size_t kWindow = kBracketPoints;  ///< the highest point and its neighbours
constexpr std::size_t kWideWindow = 5;           ///< two neighbours on each side: the model check

/// Half the signed distances from the parabola's vertex v to the vertices of the other
/// estimators: the quadratic through five points (with more than three) and a Gaussian (a
/// parabola through the logarithms, values all positive) through the three; empty with fewer
/// than three points.
std::vector<Vertex> model_deviations(const std::vector<PeakPoint>& p, const std::vector<double>& y,
                                     const Vertex& v) {
  std::vector<Vertex> d;
  if (p.size() < kWindow) return d;
  std::vector<Vertex> others;
  if (p.size() > kWindow) others.push_back(top_vertex(p, y, kWideWindow));
  if (std::all_of(y.begin(), y.end(), [](double yi) { return yi > 0.0; })) {
    std::vector<PeakPoint> lp = p;
    std::vector<double> ly(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      ly[i] = std::log(y[i]);
      lp[i].error = p[i].error / y[i];
    }
    const Vertex g = top_vertex(lp, ly, kWindow);
    others.push_back({g.x, std::exp(g.y)});
  }
  for (const auto& o : others) d.push_back({0.5 * (o.x - v.x), 0.5 * (o.y - v.y)});
  return d;
}

/// The model's own error, position and value: the part of the estimators' disagreement that the
/// points' noise does not explain. Noisy points make the three estimators disagree even on a
/// curve where all are exact (a symmetric peak); the observed half-distance D then has E[D^2] =
/// D_true^2 + var(D), with var(D) measured over draws of the points within their errors (from the
/// draws' 15.9-84.1 percentile range, which a change of the top point in a few draws does not
/// blow up; a quarter as many draws as the intervals take, from a stream of their own (seed + 1):
/// the percentiles' own scatter, ~8 %, matters little beside D). The model error is
/// sqrt(max(0, D^2 - var(D))), the larger over the two estimators.
Vertex model_spread(const std::vector<PeakPoint>& p, const std::vector<double>& y, const Vertex& v,
                    const PeakFitOptions& options) {
  Vertex spread;
  const std::vector<Vertex> d = model_deviations(p, y, v);
  if (d.empty()) return spread;
  std::vector<std::vector<double>> dx(d.size()), dy(d.size());
  std::vector<double> yd(p.size());
  NormalDraws normal(options.seed + 1);
  for (int k = 0; k < std::max(options.draws / 4, 2); ++k) {
    for (std::size_t i = 0; i < p.size(); ++i) yd[i] = p[i].y + p[i].error * normal.next();
    const Vertex vd = top_vertex(p, yd, kWindow);
    const std::vector<Vertex> dd = model_deviations(p, yd, vd);
    for (std::size_t j = 0; j < d.size() && j < dd.size(); ++j) {
      dx[j].push_back(dd[j].x);
      dy[j].push_back(dd[j].y);
    }
  }
  const double lo = 0.5 * (1.0 - kOneSigmaCoverage), hi = 1.0 - lo;
  const auto excess = [&](double observed, std::vector<double>& draws) {
    if (draws.size() < 2) return std::abs(observed);
    std::sort(draws.begin(), draws.end());
    const double sd = 0.5 * (quantile(draws, hi) - quantile(draws, lo));
    return std::sqrt(std::max(0.0, observed * observed - sd * sd));
  };
  for (std::size_t j = 0; j < d.size(); ++j) {
    spread.x = std::max(spread.x, excess(d[j].x, dx[j]));
    spread.y = std::max(spread.y, excess(d[j].y, dy[j]));
  }
  return spread;
}

/// The 68 % intervals of the vertex's position and value over draws of the points within their
/// errors. The value's draws are biased upward where several points are close to the highest
/// (the highest of noisy values exceeds their true maximum, and the draws, noisy values plus
/// noise, more so): its interval is moved down by the draws' mean bias.
void draw_intervals(const std::vector<PeakPoint>& p, const PeakFitOptions& options, PeakEstimate& e) {
  std::vector<double> xs, ys, yd(p.size());
  xs.reserve(static_cast<std::size_t>(options.draws));
  ys.reserve(static_cast<std::size_t>(options.draws));
  NormalDraws normal(options.seed);
  double y_sum = 0.0;
  for (int d = 0; d < options.draws; ++d) {
    for (std::size_t i = 0; i < p.size(); ++i) yd[i] = p[i].y + p[i].error * normal.next();
    const Vertex vd = top_vertex(p, yd, kWindow);
    xs.push_back(vd.x);
    ys.push_back(vd.y);
    y_sum += vd.y;
  }
  std::sort(xs.begin(), xs.end());
  std::sort(ys.begin(), ys.end());
  const double lo = 0.5 * (1.0 - kOneSigmaCoverage), hi = 1.0 - lo;
  const double y_bias = y_sum / static_cast<double>(ys.size()) - e.y;
  e.x_low = std::min(e.x, quantile(xs, lo));
  e.x_high = std::max(e.x, quantile(xs, hi));
  e.y_low = std::min(e.y, quantile(ys, lo) - y_bias);
  e.y_high = std::max(e.y, quantile(ys, hi) - y_bias);
}

}  // namespace

std::vector<PeakPoint> sorted_by_x(std::vector<PeakPoint> points) {
  std::sort(points.begin(), points.end(), [](const PeakPoint& a, const PeakPoint& b) { return a.x < b.x; });
  return points;
}

bool indistinct(const PeakPoint& a, const PeakPoint& b) {
  return std::abs(a.y - b.y) <= std::hypot(a.error, b.error);
}

PeakEstimate estimate_peak(std::vector<PeakPoint> points, const PeakFitOptions& options) {
  PeakEstimate e;
  if (points.empty()) return e;
  const std::vector<PeakPoint> p = sorted_by_x(std::move(points));
  std::vector<double> y(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) y[i] = p[i].y;
  e.valid = true;
  e.top = argmax(y);
  e.points = static_cast<int>(std::min(kWindow, p.size()));
  e.shape_checked = p.size() > kWindow;
  const Vertex v = top_vertex(p, y, kWindow);
  e.x = v.x;
  e.y = v.y;
  if (p.size() == 1) {
    // One point is its own value with its own error: draws would only add their sampling noise
    // (with 1 000 draws the 68 % quantiles of one Gaussian wander by ~5 % of its width).
    e.y_low = e.y - p[0].error;
    e.y_high = e.y + p[0].error;
    e.at_edge = true;
    e.x_low = e.x_high = std::numeric_limits<double>::quiet_NaN();
    return e;
  }
  draw_intervals(p, options, e);
  e.at_edge = e.x == p.front().x || e.x == p.back().x;
  if (!e.bracketed()) {
    e.x_low = e.x_high = std::numeric_limits<double>::quiet_NaN();
    return e;
  }
  const Vertex model = model_spread(p, y, v, options);
  e.model_error = model.x;
  e.x_low = e.x - std::hypot(e.x - e.x_low, model.x);
  e.x_high = e.x + std::hypot(e.x_high - e.x, model.x);
  e.y_low = e.y - std::hypot(e.y - e.y_low, model.y);
  e.y_high = e.y + std::hypot(e.y_high - e.y, model.y);
  // The peak is no further out than the points that were sampled.
  e.x_low = std::max(e.x_low, p.front().x);
  e.x_high = std::min(e.x_high, p.back().x);
  return e;
}

Curvature curvature_near(std::vector<PeakPoint> points, double x, double reach) {
  Curvature k;
  std::vector<PeakPoint> p;
  for (const auto& q : sorted_by_x(std::move(points)))
    if (std::abs(q.x - x) <= reach) p.push_back(q);
  k.points = static_cast<int>(p.size());
  if (p.size() < 3) return k;
  std::vector<double> y(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) y[i] = p[i].y;
  const Quadratic q = fit_quadratic(p, y, 0, p.size() - 1, argmax(y));
  k.value = q.c / (q.scale * q.scale);
  k.error = std::sqrt(q.var_c) / (q.scale * q.scale);
  return k;
}

}  // namespace boycott::stats
