#include "stats/point_error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "stats/distributions.hpp"

namespace boycott::stats {
namespace {

struct Scatter {
  double mean = 0.0, sd = 0.0;
};

Scatter scatter_of(const std::vector<double>& w) {
  Scatter s;
  const double n = static_cast<double>(w.size());
  for (double x : w) s.mean += x / n;
  double ss = 0.0;
  for (double x : w) ss += (x - s.mean) * (x - s.mean);
  s.sd = w.size() >= 2 ? std::sqrt(ss / (n - 1.0)) : std::numeric_limits<double>::quiet_NaN();
  return s;
}

// The probability that the values scatter this much or less, given their own errors: Fisher's F
// of their variance over the mean of their squared errors, with n - 1 and the errors' own
// (Welch-Satterthwaite) degrees of freedom. Near 1: they scatter more than their errors say; near
// 0: less. A chi-square that took the errors as exact would cry wolf for errors from few degrees
// of freedom (a short run's two halves: 1): on runs of 10 correlation times it flagged "scatter
// more" for 32-87 % of points of 2-10 replicas, and 9-28 % at 50.
double agreement_cdf(const Scatter& s, double mean_sq_error, double error_dof, double n) {
  return f_cdf(s.sd * s.sd / mean_sq_error, n - 1.0, error_dof);
}

}  // namespace

ReplicaMean replica_mean(const std::vector<double>& w) {
  ReplicaMean m;
  double sum = 0.0;
  for (double x : w) sum += x;
  const double n = static_cast<double>(w.size());
  m.mean = w.size() == 1 ? w.front() : sum / n;
  if (w.size() >= 2) {
    double ss = 0.0;
    for (double x : w) ss += (x - m.mean) * (x - m.mean);
    m.between_stderr = std::sqrt(ss / (n - 1.0)) / std::sqrt(n);
  }
  return m;
}

PointError point_error(const std::vector<RunEstimate>& runs, int stage_one) {
  PointError e;
  if (runs.empty()) return e;
  if (runs.size() == 1) {
    const auto& r = runs.front();
    if (!r.stderr_m_s) return e;
    e.plain_m_s = r.stderr_m_s;
    if (r.dof && std::isfinite(*r.dof) && *r.dof > 0.0) {
      e.dof = *r.dof;
      e.error_m_s = *r.stderr_m_s * one_sigma_t_factor(e.dof);
      e.basis = "single_run";
    } else {
      e.dof = std::numeric_limits<double>::infinity();
      e.error_m_s = r.stderr_m_s;
      e.basis = "single_run_plain";
    }
    return e;
  }
  std::vector<double> w;
  for (const auto& r : runs) w.push_back(r.w_m_s);
  const Scatter all = scatter_of(w);
  const double n = static_cast<double>(runs.size());
  e.plain_m_s = all.sd / std::sqrt(n);
  e.dof = n - 1.0;
  if (stage_one >= 2 && static_cast<int>(runs.size()) >= stage_one) {
    const Scatter first = scatter_of({w.begin(), w.begin() + stage_one});
    e.dof = stage_one - 1.0;
    e.plain_m_s = first.sd / std::sqrt(n);
    e.error_m_s = one_sigma_t_factor(e.dof) * *e.plain_m_s;
    e.basis = "two_stage_stein";
    return e;
  }
  e.error_m_s = one_sigma_t_factor(e.dof) * *e.plain_m_s;
  e.basis = "between_replicas_t";
  const bool all_within = std::all_of(runs.begin(), runs.end(), [](const RunEstimate& r) {
    return r.stderr_m_s && std::isfinite(*r.stderr_m_s) && *r.stderr_m_s > 0.0;
  });
  if (!all_within) return e;
  // The pooled within-run error of the mean, and how well the scatter agrees with it.
  double var = 0.0;
  for (const auto& r : runs) var += *r.stderr_m_s * *r.stderr_m_s / (n * n);
  double within_dof = 0.0;  // Welch-Satterthwaite over the runs' own degrees of freedom
  bool dofs = true;
  for (const auto& r : runs) {
    if (!r.dof || !(*r.dof > 0.0)) dofs = false;
    if (dofs) within_dof += std::pow(*r.stderr_m_s / n, 4) / *r.dof;
  }
  const double within_plain = std::sqrt(var);
  const double within_nu =
      dofs && within_dof > 0.0 ? var * var / within_dof : std::numeric_limits<double>::infinity();
  const double within = within_plain * one_sigma_t_factor(within_nu);
  const double p = agreement_cdf(all, var * n, within_nu, n);
  if (p > 0.975) {
    e.basis += fmt::format("; the replicas scatter more than their own errors (F test p = {:.3f})", 1.0 - p);
    if (within > *e.error_m_s) e.error_m_s = within, e.plain_m_s = within_plain, e.dof = within_nu;
  } else if (p < 0.025) {
    e.basis = fmt::format(
        "within_runs_pooled; the replicas agree more closely than their own errors say "
        "(F test p = {:.3f})",
        p);
    if (within > *e.error_m_s) {
      e.error_m_s = within, e.plain_m_s = within_plain, e.dof = within_nu;
    } else {
      e.basis = "between_replicas_t" + e.basis.substr(std::string("within_runs_pooled").size());
    }
  }
  return e;
}

std::optional<double> ratio_error(double w, const PointError& e, double w90, const PointError& e90) {
  if (!e.plain_m_s || !e90.plain_m_s || w90 == 0.0) return std::nullopt;
  const double r = w / w90;
  const double a = *e.plain_m_s / w90, b = r * *e90.plain_m_s / w90;
  const double var = a * a + b * b;
  if (var == 0.0) return 0.0;
  return std::sqrt(var) * one_sigma_t_factor(welch_dof(a * a, e.dof, b * b, e90.dof));
}

double welch_dof(double var_a, double dof_a, double var_b, double dof_b) {
  // Each part's share of var^2 over its dof + 2: s^4 nu / (nu + 2) is the unbiased estimate of
  // sigma^4 (E s^4 = sigma^4 (nu + 2) / nu), where Satterthwaite's s^4 / nu is biased high.
  const auto term = [](double v, double nu) { return std::isinf(nu) ? 0.0 : v * v / (nu + 2.0); };
  const double denom = term(var_a, dof_a) + term(var_b, dof_b);
  if (!(denom > 0.0)) return std::numeric_limits<double>::infinity();
  const double nu = (var_a + var_b) * (var_a + var_b) / denom - 2.0;
  // At least the smaller part's own dof (reached where that part is all of the variance).
  return std::max(nu, std::min(dof_a, dof_b));
}

int stein_replicas_needed(const std::vector<double>& stage_one_w, double target_rel_error, int max) {
  const int n0 = static_cast<int>(stage_one_w.size());
  const Scatter s = scatter_of(stage_one_w);
  const double t = one_sigma_t_factor(n0 - 1.0);
  int n = n0;
  while (n < max && t * s.sd / std::sqrt(static_cast<double>(n)) > target_rel_error * std::abs(s.mean)) ++n;
  return n;
}

}  // namespace boycott::stats
