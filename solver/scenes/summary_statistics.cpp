#include "scenes/summary_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include <unistd.h>

#include <fmt/format.h>

#include "scenes/run_common.hpp"

namespace boycott::scenes {

void add_warning(nlohmann::json& j, const std::string& text) {
  if (!j.contains("warnings")) j["warnings"] = nlohmann::json::array();
  j["warnings"].push_back(text);
  // On a terminal the live progress line may stand unfinished: clear it so the warning starts a
  // line of its own (the progress line is drawn again below it).
  if (output_rank())
    std::fprintf(stderr, "%swarning: %s\n", isatty(STDERR_FILENO) ? "\r\033[K" : "", text.c_str());
}

void report_window_error(nlohmann::json& j, const std::string& prefix, const std::string& what,
                         const stats::WindowError& w, bool warn, double transient_end_s) {
  const auto& e = w.e;
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  j[prefix + "stderr_m_s"] = num(w.err.stderr_of_mean);
  j[prefix + "error_m_s"] = num(w.err.covering_error);
  j[prefix + "error_dof"] = num(w.err.dof);
  j[prefix + "correlation_time_s"] = num(w.correlation_time_s());
  j[prefix + "correlation_time_upper_s"] = num(w.correlation_time_upper_s());
  j[prefix + "effective_samples"] = num(e.effective_samples);
  j[prefix + "window_correlation_times"] = num(e.correlation_times);
  j[prefix + "error_method"] = stats::error_method_name(w.err.basis);
  j[prefix + "error_batches"] = w.err.batches > 0 ? nlohmann::json(w.err.batches) : nlohmann::json(nullptr);
  if (!warn) return;
  const std::string text = stats::window_warning(w, what, transient_end_s);
  if (!text.empty()) add_warning(j, text);
}

stats::ChosenWindow averaging_window(const WindowStart& start, const stats::StepSeries& s,
                                     const std::vector<double>& collected, double now_s,
                                     const stats::TwoStagePlan* plan) {
  if (!start.automatic) return stats::ChosenWindow{s, collected, start.collect_from_s()};
  return plan && plan->set() ? stats::cut_window_at(s, collected, start.collect_from_s(), now_s, plan->cut)
                             : stats::cut_at_transient(s, collected, start.collect_from_s(), now_s);
}

double report_transient(nlohmann::json& j, const std::string& what, const stats::StepSeries& s,
                        const std::vector<double>& window, double window_from_s, bool warn) {
  j["average_from_s"] = window_from_s;
  std::vector<double> x(s.before);
  x.insert(x.end(), window.begin(), window.end());
  const stats::TransientEnd cut = stats::transient_end(x);
  if (!cut.estimated) {
    j["transient_end_s"] = nullptr;
    return std::numeric_limits<double>::quiet_NaN();
  }
  // Sample k's time: counted back from the window's start through the steps before it, or on
  // through the window's steps (their mean length where a resumed run lacks them).
  const auto n_before = static_cast<std::int64_t>(s.before.size());
  double t = window_from_s;
  if (cut.start < n_before) {
    for (std::int64_t k = n_before - 1; k >= cut.start; --k) t -= s.before_dt[static_cast<std::size_t>(k)];
  } else {
    const double mean_dt = window.empty() ? 0.0
                                          : (j.value("simulated_time_s", window_from_s) - window_from_s) /
                                                static_cast<double>(window.size());
    for (std::int64_t k = n_before; k < cut.start; ++k) {
      const auto i = static_cast<std::size_t>(k - n_before);
      t += i < s.window_dt.size() ? s.window_dt[i] : mean_dt;
    }
  }
  // Summed back, the steps leave round-off (-3e-17 s) where the transient ends at the run's start.
  if (cut.start == 0 && s.before_whole) t = 0.0;
  j["transient_end_s"] = t;
  j["transient_detection_from_s"] = s.before_whole ? 0.0 : window_from_s - [&] {
    double d = 0.0;
    for (double v : s.before_dt) d += v;
    return d;
  }();
  if (warn && cut.start > n_before && stats::transient_biases_mean(x, n_before, cut.detected))
    add_warning(
        j, fmt::format("the start-up transient of {} ends at {:.3g} s, after time.average_from = {:g} s, "
                       "and the samples between shift the mean beyond their noise: average from {:.3g} s "
                       "or later",
                       what, t, window_from_s, t));
  return t;
}

void report_time_weighted(nlohmann::json& j, const std::string& prefix, const std::string& what,
                          const std::vector<double>& window, const stats::StepSeries& s, double error,
                          bool warn) {
  const std::string key = prefix + "time_weighted_m_s";
  if (!s.dt_whole || s.window_dt.size() != window.size() || window.empty()) {
    j[key] = nullptr;
    return;
  }
  double sum = 0.0, span = 0.0, plain = 0.0;
  for (std::size_t i = 0; i < window.size(); ++i) {
    sum += window[i] * s.window_dt[i];
    span += s.window_dt[i];
    plain += window[i] / static_cast<double>(window.size());
  }
  const double weighted = sum / span;
  j[key] = weighted;
  if (warn && std::isfinite(error) && std::abs(weighted - plain) > error)
    add_warning(
        j, fmt::format("the step length varied (CFL limit): the time-weighted mean of {} ({:.6g}) differs "
                       "from the mean over steps ({:.6g}, Eq. 29) by more than its error ({:.3g})",
                       what, weighted, plain, error));
}

void report_settling_statistics(nlohmann::json& j, const stats::StepSeries& s,
                                const std::vector<double>& window, const stats::WindowError& w, bool warn) {
  const double window_from_s = w.from_s;
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  const double transient_s = report_transient(j, "<w_p>", s, window, window_from_s, warn);
  report_window_error(j, "settling_velocity_", "<w_p>", w, warn, transient_s);
  report_time_weighted(j, "settling_velocity_", "<<w_p>>", window, s, w.err.covering_error, warn);
  j["settling_velocity_rel_stderr"] = num(std::abs(w.err.stderr_of_mean / w.e.mean));
}

bool is_settling_statistics_warning(const std::string& text) {
  for (const char* opening :
       {"the averaging window (", "the start-up transient of ", "the step length varied"})
    if (text.rfind(opening, 0) == 0) return true;
  return false;
}

}  // namespace boycott::scenes
