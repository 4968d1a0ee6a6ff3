#pragma once
// Synthetic curves for the peak tests (test_peak_fit.cpp, test_peak_coverage.cpp), as a study sees
// them: a coarse grid of angles (15 to 90 deg every 15, six points), then points added one at a
// time by the refinement rule (stats/peak_refine.hpp), each with noise of known standard
// deviation (stated as its error) until the rule stops; resolution 2.5 deg (a uniform grid of
// that resolution: 31 points), at most 8 added. The curves look like an acceleration ratio: 1
// far from the peak, 2.25 at it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "stats/peak_fit.hpp"
#include "stats/peak_refine.hpp"

namespace peak_curves {

using namespace boycott::stats;

constexpr double kLo = 15.0, kHi = 90.0, kStep = 15.0;
constexpr double kResolution = 2.5;
constexpr int kMaxPoints = 8;
constexpr int kUniformGridPoints = 31;  // 15, 17.5, ..., 90

/// A family of curves: the value at x of the curve whose peak parameter is x0, and the range
/// x0 is drawn from.
struct Family {
  std::string name;
  std::function<double(double, double)> f;
  double x0_lo, x0_hi;
  double noise;  ///< standard deviation of each point, its stated error
};

inline Family symmetric() {
  return {"symmetric",
          [](double x, double x0) { return 1.0 + 1.25 * std::exp(-std::pow((x - x0) / 15.0, 2) / 2.0); },
          45.0, 75.0, 0.02};
}
/// A Gaussian in -log(100 - x): slow on the low side, steep towards 90 deg; smooth, so a
/// parabola is right only near the top.
inline Family skewed() {
  return {"skewed",
          [](double x, double x0) {
            const double g = std::log(100.0 - x0) - std::log(100.0 - x);
            return 1.0 + 1.25 * std::exp(-g * g / (2.0 * 0.45 * 0.45));
          },
          45.0, 75.0, 0.02};
}
/// A peak beyond 90 deg: the range's maximum is at its edge.
inline Family edge() {
  return {"edge",
          [](double x, double x0) { return 1.0 + 1.25 * std::exp(-std::pow((x - x0) / 20.0, 2) / 2.0); },
          95.0, 110.0, 0.02};
}
/// exp(-u^8): a top about 30 deg wide that drops by less than the noise over +-12 deg.
inline Family flat_top() {
  return {"flat top",
          [](double x, double x0) { return 1.0 + 1.25 * std::exp(-std::pow((x - x0) / 22.0, 8)); }, 50.0,
          70.0, 0.02};
}

/// One refined curve: where the rule stopped and what the estimate said, beside the truth.
struct Trial {
  double true_x = 0, true_y = 0;
  PeakEstimate peak;
  RefineStop stop = RefineStop::kContinue;
  std::string why;
  int added = 0;
};

/// The maximum of f over [kLo, kHi] on a 0.001 grid.
inline std::pair<double, double> true_peak(const Family& fam, double x0) {
  std::pair<double, double> best{kLo, -1e300};
  for (int k = 0; k <= 75000; ++k) {
    const double x = kLo + 0.001 * k;
    if (const double v = fam.f(x, x0); v > best.second) best = {x, v};
  }
  return best;
}

inline std::vector<Trial> refine_curves(const Family& fam, int curves, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, fam.noise);
  std::uniform_real_distribution<double> u(fam.x0_lo, fam.x0_hi);
  std::vector<Trial> out;
  for (int t = 0; t < curves; ++t) {
    const double x0 = u(rng);
    Trial tr;
    std::tie(tr.true_x, tr.true_y) = true_peak(fam, x0);
    std::vector<PeakPoint> pts;
    for (double x = kLo; x <= kHi + 1e-9; x += kStep)
      pts.push_back({x, fam.f(x, x0) + noise(rng), fam.noise});
    while (true) {
      const RefineStep s = next_refinement(pts, tr.added, {kResolution, kMaxPoints});
      if (s.stop != RefineStop::kContinue) {
        tr.peak = s.peak;
        tr.stop = s.stop;
        tr.why = s.why;
        break;
      }
      pts.push_back({s.next_x, fam.f(s.next_x, x0) + noise(rng), fam.noise});
      ++tr.added;
    }
    out.push_back(tr);
  }
  return out;
}

struct Summary {
  double within = 0, cover_x = 0, cover_y = 0, mean_points = 0;
  int most_points = 0;
  std::map<RefineStop, int> stops;
};

/// `shrink` < 1 judges intervals narrowed about the estimate by that factor on each side.
inline Summary summarise(const std::vector<Trial>& trials, double shrink = 1.0) {
  Summary s;
  const double n = static_cast<double>(trials.size());
  for (const auto& t : trials) {
    const PeakEstimate& e = t.peak;
    const double xl = e.x - shrink * (e.x - e.x_low), xh = e.x + shrink * (e.x_high - e.x);
    const double yl = e.y - shrink * (e.y - e.y_low), yh = e.y + shrink * (e.y_high - e.y);
    s.within += (std::abs(e.x - t.true_x) <= kResolution) / n;
    s.cover_x += (xl <= t.true_x + 1e-9 && t.true_x - 1e-9 <= xh) / n;
    s.cover_y += (yl <= t.true_y && t.true_y <= yh) / n;
    const int points = 6 + t.added;
    s.mean_points += points / n;
    s.most_points = std::max(s.most_points, points);
    ++s.stops[t.stop];
  }
  return s;
}

inline void print(const std::string& name, const Summary& s) {
  std::printf("coverage, %s: position %.3f, value %.3f; within the resolution %.3f; points %.2f (at most %d)",
              name.c_str(), s.cover_x, s.cover_y, s.within, s.mean_points, s.most_points);
  for (const auto& [stop, n] : s.stops) std::printf(", %s %d", to_string(stop), n);
  std::printf("\n");
}

}  // namespace peak_curves
