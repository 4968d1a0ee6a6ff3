#include "driver/report/peak.hpp"

#include <cmath>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "driver/report/report_util.hpp"

namespace boycott::driver {
namespace {

/// A number, or nothing where it is not known (NaN: an angle's interval from too few points).
std::optional<double> known(double v) {
  return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

nlohmann::json json_of(const PeakRow& r) {
  const auto opt = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  return {{"group", r.group},
          {"setting", r.setting},
          {"angle_deg", r.peak.x},
          {"angle_err_deg", opt(known(r.peak.x_error()))},
          {"angle_low_deg", opt(known(r.peak.x_low))},
          {"angle_high_deg", opt(known(r.peak.x_high))},
          {"mean_settling_velocity_m_s", r.w_m_s},
          {"error_m_s", r.peak.y_error()},
          {"r_acc", opt(r.r_acc)},
          {"r_acc_err", opt(r.r_acc_err)},
          {"n_points", r.points},
          {"n_added", r.added},
          {"resolved", r.resolved},
          {"status", r.status},
          {"objective", r.objective},
          {"why", r.why}};
}

std::string csv(const std::vector<PeakRow>& rows) {
  std::string s =
      "group,setting,angle_deg,angle_err_deg,angle_low_deg,angle_high_deg,mean_settling_velocity_m_s,error_m_"
      "s,"
      "r_acc,r_acc_err,n_points,n_added,resolved,status,objective,why\n";
  const auto opt = [](const std::optional<double>& v) {
    return v ? fmt::format("{:.6g}", *v) : std::string();
  };
  const auto err = [](double v) { return std::isfinite(v) ? fmt::format("{:.4g}", v) : std::string(); };
  for (const auto& r : rows)
    s += report::csv_line({r.group, r.setting, fmt::format("{:.6g}", r.peak.x), err(r.peak.x_error()),
                           opt(known(r.peak.x_low)), opt(known(r.peak.x_high)),
                           fmt::format("{:.9g}", r.w_m_s), fmt::format("{:.4g}", r.peak.y_error()),
                           opt(r.r_acc), opt(r.r_acc_err), std::to_string(r.points), std::to_string(r.added),
                           r.resolved ? "true" : "false", r.status, r.objective, r.why});
  return s;
}

std::string table(const std::vector<PeakRow>& rows) {
  if (rows.empty()) return "(no curve with a finished point)\n";
  report::TextTable t({"group", "angle +- 68 % (deg)", "[low, high]", "<<w_p>> +- 68 % (mm/s)",
                       "r_acc +- 68 %", "points (added)", "resolved", "setting"},
                      {false, true, false, true, true, true, false, false});
  std::string notes;
  for (const auto& r : rows) {
    const bool interval = std::isfinite(r.peak.x_error());
    t.add({r.group,
           interval ? fmt::format("{:.1f} +- {:.1f}", r.peak.x, r.peak.x_error())
                    : fmt::format("{:.1f} (highest point)", r.peak.x),
           interval ? fmt::format("[{:.1f}, {:.1f}]", r.peak.x_low, r.peak.x_high) : std::string("-"),
           fmt::format("{:.2f} +- {:.2f}", r.w_m_s * 1e3, r.peak.y_error() * 1e3),
           r.r_acc ? fmt::format("{:.3f} +- {:.3f}", *r.r_acc, r.r_acc_err.value_or(0.0)) : "-",
           fmt::format("{} ({})", r.points, r.added), r.resolved ? "yes" : "no (" + r.status + ")",
           r.setting});
    notes +=
        fmt::format("{}{}: {}: {}\n", r.group, r.setting.empty() ? "" : " " + r.setting, r.status, r.why);
  }
  return t.str() + notes;
}

}  // namespace

std::string format_peak(const std::vector<PeakRow>& rows, ListingFormat f) {
  if (f == ListingFormat::kCsv) return csv(rows);
  if (f == ListingFormat::kJson) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& r : rows) j.push_back(json_of(r));
    return j.dump(2) + "\n";
  }
  return table(rows);
}

}  // namespace boycott::driver
