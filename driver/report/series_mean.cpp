#include "driver/report/series_mean.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "driver/report/report_util.hpp"
#include "stats/transient.hpp"
#include "stats/window_error.hpp"

namespace boycott::driver::report {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One column over rows [first, n): the window's error as a run reports it, its transient end
// found over the whole column. Row k is at time[k] (s, or the row index); the window ends one mean
// spacing after its last row, as a run's window ends one step after its last sample.
SeriesMean column_mean(const std::string& name, const std::vector<double>& x, std::size_t first,
                       const std::vector<double>& time) {
  SeriesMean m;
  m.name = name;
  m.velocity = name.size() > 4 && name.ends_with("_m_s");
  const std::vector<double> window(x.begin() + static_cast<std::ptrdiff_t>(first), x.end());
  m.samples = window.size();
  m.average_from = time[first];
  const double now = time.back() + (time.back() - time[first]) / static_cast<double>(window.size() - 1);
  const stats::WindowError w = stats::window_error(window, m.average_from, now);
  m.mean = w.e.mean;
  m.error = w.err.covering_error;
  m.stderr_of_mean = w.err.stderr_of_mean;
  m.dof = w.err.dof;
  m.basis = stats::error_method_name(w.err.basis);
  m.batches = w.err.batches;
  m.tau_int = w.correlation_time_s();
  m.tau_int_upper = w.correlation_time_upper_s();
  m.correlation_times = w.e.correlation_times;
  const stats::TransientEnd cut = stats::transient_end(x);
  m.transient_end = cut.estimated ? time[static_cast<std::size_t>(cut.start)] : kNaN;
  const std::string warning = stats::window_warning(w, name, m.transient_end);
  if (!warning.empty()) m.warnings.push_back(warning);
  if (cut.estimated && cut.start > static_cast<std::int64_t>(first) &&
      stats::transient_biases_mean(x, static_cast<std::int64_t>(first), cut.detected))
    m.warnings.push_back(
        fmt::format("the start-up transient of {} ends at {:.4g}, after the window's start, and "
                    "the samples between shift the mean beyond their noise: average from there",
                    name, m.transient_end));
  return m;
}

std::string num(double v) {
  return std::isfinite(v) ? fmt::format("{:.6g}", v) : "";
}

}  // namespace

AverageFrom parse_average_from(const std::string& s) {
  AverageFrom a;
  if (s.empty()) return a;
  if (s == "auto") {
    a.automatic = true;
    return a;
  }
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !std::isfinite(v))
    throw InputError(fmt::format("--average-from takes a time or 'auto', not '{}'", s));
  a.from = v;
  return a;
}

std::vector<SeriesMean> series_means(const SeriesTable& t, const std::vector<std::string>& wanted,
                                     const AverageFrom& from) {
  const std::size_t n = t.columns.front().size();
  // Row k's time: the time column, or the row index.
  std::vector<double> time(n);
  for (std::size_t k = 0; k < n; ++k) time[k] = t.time_s ? (*t.time_s)[k] : static_cast<double>(k);
  std::size_t first = 0;
  if (from.from) {
    // The first row at or after T (a rounding below T in the file's digits counts as at T).
    const double slack = 1e-9 * std::max(1.0, std::abs(*from.from));
    first = static_cast<std::size_t>(std::lower_bound(time.begin(), time.end(), *from.from - slack) -
                                     time.begin());
    if (first + 8 > n)
      throw InputError(
          fmt::format("--average-from {:g} leaves {} rows of {}: the error of a mean needs 8 at least",
                      *from.from, first < n ? n - first : 0, n));
  }
  std::vector<std::size_t> picked;
  for (const auto& w : wanted) {
    const auto it = std::find(t.names.begin(), t.names.end(), w);
    if (it == t.names.end())
      throw InputError(fmt::format("no numeric column '{}' (there are: {})", w, fmt::join(t.names, ", ")));
    picked.push_back(static_cast<std::size_t>(it - t.names.begin()));
  }
  if (wanted.empty())
    for (std::size_t c = 0; c < t.names.size(); ++c) picked.push_back(c);
  std::vector<SeriesMean> rows;
  for (std::size_t c : picked) {
    std::size_t start = first;
    if (from.automatic) {
      const stats::TransientEnd cut = stats::transient_end(t.columns[c]);
      start = cut.estimated ? static_cast<std::size_t>(cut.start) : 0;
    }
    rows.push_back(column_mean(t.names[c], t.columns[c], start, time));
  }
  return rows;
}

std::string format_series_means(const std::vector<SeriesMean>& rows, ListingFormat format, bool timed) {
  const bool all_velocity = std::all_of(rows.begin(), rows.end(), [](const auto& r) { return r.velocity; });
  const std::string error = all_velocity ? "error_m_s" : "error", unit = timed ? "_s" : "_rows";
  const std::vector<std::string> head{"column",
                                      "mean",
                                      "samples",
                                      error,
                                      "basis",
                                      "dof",
                                      "tau_int" + unit,
                                      "tau_int_upper" + unit,
                                      "correlation_times",
                                      "average_from" + unit,
                                      "transient_end" + unit,
                                      "warnings"};
  if (format == ListingFormat::kJson) {
    nlohmann::json j = nlohmann::json::array();
    auto val = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
    for (const auto& r : rows)
      j.push_back({{"column", r.name},
                   {"mean", val(r.mean)},
                   {"samples", r.samples},
                   {r.velocity ? "error_m_s" : "error", val(r.error)},
                   {"stderr", val(r.stderr_of_mean)},
                   {"basis", r.basis},
                   {"batches", r.batches},
                   {"dof", val(r.dof)},
                   {head[6], val(r.tau_int)},
                   {head[7], val(r.tau_int_upper)},
                   {"correlation_times", val(r.correlation_times)},
                   {head[9], val(r.average_from)},
                   {head[10], val(r.transient_end)},
                   {"warnings", r.warnings}});
    return j.dump(2) + "\n";
  }
  std::vector<std::vector<std::string>> cells;
  for (const auto& r : rows)
    cells.push_back({r.name, num(r.mean), std::to_string(r.samples), num(r.error), r.basis, num(r.dof),
                     num(r.tau_int), num(r.tau_int_upper), num(r.correlation_times), num(r.average_from),
                     num(r.transient_end), fmt::format("{}", fmt::join(r.warnings, " | "))});
  if (format == ListingFormat::kCsv) {
    std::string out = csv_line(head);
    for (const auto& c : cells) out += csv_line(c);
    return out;
  }
  TextTable table(head, {false, true, true, true, false, true, true, true, true, true, true, false});
  for (auto& c : cells) table.add(c);
  return table.str();
}

}  // namespace boycott::driver::report
