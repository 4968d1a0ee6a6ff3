#include "driver/curve.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "driver/report_util.hpp"

namespace boycott::driver {

using report::marker;
using report::ticks;
using report::xml_escape;

CurveFormat parse_curve_format(const std::string& s) {
  if (s == "table") return CurveFormat::kTable;
  if (s == "csv") return CurveFormat::kCsv;
  if (s == "json") return CurveFormat::kJson;
  throw InputError(fmt::format("--format {} is not known: must be table, csv or json", s));
}

std::string format_curve(const std::vector<CurvePoint>& pts, CurveFormat f) {
  std::string s;
  auto opt = [](const std::optional<double>& v) { return v ? fmt::format("{:.6g}", *v) : std::string(); };
  auto opt9 = [](const std::optional<double>& v) { return v ? fmt::format("{:.9g}", *v) : std::string(); };
  auto opt_json = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  if (f == CurveFormat::kCsv) {
    s = "group,angle_deg,mean_settling_velocity_m_s,stderr_m_s,n_replicas,between_replica_stderr_m_s,"
        "mean_within_run_stderr_m_s,r_acc,r_acc_err,error_method,case_id,setting\n";
    for (const auto& p : pts)
      s += fmt::format("{},{:g},{:.9g},{},{},{},{},{},{},{},{},{}\n", p.group, p.angle_deg, p.w_m_s,
                       opt9(p.w_err_m_s), p.n_replicas, opt9(p.between_replica_stderr_m_s),
                       opt9(p.mean_within_run_stderr_m_s), opt(p.r_acc), opt(p.r_acc_err), p.error_method,
                       p.case_id, report::csv_field(p.setting));
  } else if (f == CurveFormat::kJson) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& p : pts) {
      nlohmann::json e = {{"group", p.group},
                          {"angle_deg", p.angle_deg},
                          {"mean_settling_velocity_m_s", p.w_m_s},
                          {"case_id", p.case_id},
                          {"setting", p.setting}};
      e["stderr_m_s"] = opt_json(p.w_err_m_s);
      e["n_replicas"] = p.n_replicas;
      e["between_replica_stderr_m_s"] = opt_json(p.between_replica_stderr_m_s);
      e["mean_within_run_stderr_m_s"] = opt_json(p.mean_within_run_stderr_m_s);
      e["error_method"] = p.error_method;
      e["r_acc"] = opt_json(p.r_acc);
      e["r_acc_err"] = opt_json(p.r_acc_err);
      e["replica_case_ids"] = p.replica_case_ids;
      e["replica_mean_settling_velocities_m_s"] = p.replica_w_m_s;
      j.push_back(e);
    }
    s = j.dump(2) + "\n";
  } else if (pts.empty()) {
    s = "(no finished cases)\n";
  } else {
    // A missing error is "n/a", never a zero that reads as an exact value. With replicas the
    // error of <<w_p>> is their scatter (between, the error of their mean); "within" is the mean
    // of the runs' own errors, one run's: honest run errors give between x sqrt(n) ~ within.
    auto mm = [](const std::optional<double>& v) { return v ? fmt::format("{:.4f}", *v * 1e3) : "n/a"; };
    report::TextTable t({"group", "angle", "<<w_p>> (mm/s)", "n", "between (mm/s)", "within, 1 run (mm/s)",
                         "r_acc", "error method", "setting"},
                        {false, true, true, true, true, true, true, false, false});
    for (const auto& p : pts) {
      const std::string r = p.r_acc ? fmt::format("{:.3f} +- {}", *p.r_acc,
                                                  p.r_acc_err ? fmt::format("{:.3f}", *p.r_acc_err) : "n/a")
                                    : "-";
      t.add({p.group, fmt::format("{:g}", p.angle_deg),
             fmt::format("{:.4f} +- {}", p.w_m_s * 1e3, mm(p.w_err_m_s)), std::to_string(p.n_replicas),
             p.n_replicas >= 2 ? mm(p.between_replica_stderr_m_s) : "-", mm(p.mean_within_run_stderr_m_s), r,
             p.error_method, p.setting});
    }
    s = t.str();
  }
  return s;
}

namespace {

// One line per group, or per (group, setting) when a group sweeps more than the angle.
std::string series_of(const CurvePoint& p) {
  return p.setting.empty() ? p.group : p.group + " " + p.setting;
}

struct Panel {
  double x0, y0, w, h;  // pixel box of the plot area
  double vmin, vmax;    // data range of y
  double px(double angle) const { return x0 + (angle - 10.0) / 85.0 * w; }
  double py(double v) const { return y0 + h - (v - vmin) / (vmax - vmin) * h; }
};

/// The angles where the paper places its critical angles: a peak value stated without its
/// angle is drawn over this range.
constexpr double kPeakFrom = 60.0, kPeakTo = 75.0;

}  // namespace

std::string curve_svg(const std::vector<CurvePoint>& pts, const std::string& title,
                      const std::vector<PaperValue>* paper) {
  std::vector<std::string> groups;
  for (const auto& p : pts)
    if (std::find(groups.begin(), groups.end(), series_of(p)) == groups.end()) groups.push_back(series_of(p));
  // A paper value takes the colour of the first series of its group, grey when the study has none.
  auto paper_color = [&](const PaperValue& v) -> const char* {
    for (std::size_t g = 0; g < groups.size(); ++g)
      for (const auto& p : pts)
        if (series_of(p) == groups[g] && p.group == v.group) return report::color(g);
    return "#777";
  };

  std::string s =
      "<svg xmlns='http://www.w3.org/2000/svg' width='1000' height='440' font-family='sans-serif' "
      "font-size='13'>\n<rect width='1000' height='440' fill='white'/>\n";
  s += fmt::format("<text x='500' y='22' text-anchor='middle' font-size='15'>{}</text>\n", xml_escape(title));
  for (int panel = 0; panel < 2; ++panel) {
    // Left: <<w_p>> in mm/s; right: r_acc (dimensionless).
    auto value = [&](const CurvePoint& p) -> std::optional<std::pair<double, double>> {
      // An unknown error draws no bar.
      if (panel == 0) return std::pair{p.w_m_s * 1e3, p.w_err_m_s.value_or(0.0) * 1e3};
      if (!p.r_acc) return std::nullopt;
      return std::pair{*p.r_acc, p.r_acc_err.value_or(0.0)};
    };
    // Each replica's value: its <<w_p>>, or its ratio to the point's 90 deg mean.
    auto replica_values = [&](const CurvePoint& p) {
      std::vector<double> v;
      if (p.n_replicas < 2) return v;
      for (double w : p.replica_w_m_s) {
        if (panel == 0)
          v.push_back(w * 1e3);
        else if (p.r_acc && p.w_m_s != 0.0)
          v.push_back(w * *p.r_acc / p.w_m_s);
      }
      return v;
    };
    const char* quantity = panel == 0 ? "mean_settling_velocity_m_s" : "r_acc";
    const double scale = panel == 0 ? 1e3 : 1.0;
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& p : pts) {
      if (auto v = value(p)) {
        lo = std::min(lo, v->first - v->second);
        hi = std::max(hi, v->first + v->second);
      }
      for (double r : replica_values(p)) lo = std::min(lo, r), hi = std::max(hi, r);
    }
    if (paper)
      for (const auto& v : *paper)
        if (v.quantity == quantity) lo = std::min(lo, v.value * scale), hi = std::max(hi, v.value * scale);
    if (!std::isfinite(lo)) lo = 0, hi = 1;
    if (panel == 1) lo = std::min(lo, 1.0), hi = std::max(hi, 1.0);
    if (hi - lo < 1e-12) lo -= 0.5, hi += 0.5;
    const double pad = 0.08 * (hi - lo);
    Panel pn{80.0 + panel * 490.0, 50.0, 400.0, 320.0, lo - pad, hi + pad};
    s += fmt::format("<rect x='{}' y='{}' width='{}' height='{}' fill='none' stroke='black'/>\n", pn.x0,
                     pn.y0, pn.w, pn.h);
    for (double a = 15; a <= 90; a += 15)
      s += fmt::format(
          "<line x1='{0:.1f}' y1='{1:.1f}' x2='{0:.1f}' y2='{2:.1f}' stroke='black'/><text x='{0:.1f}' "
          "y='{3:.1f}' text-anchor='middle'>{4:g}</text>\n",
          pn.px(a), pn.y0 + pn.h, pn.y0 + pn.h - 5, pn.y0 + pn.h + 18, a);
    for (double v : ticks(pn.vmin, pn.vmax))
      s += fmt::format(
          "<line x1='{0:.1f}' y1='{1:.1f}' x2='{2:.1f}' y2='{1:.1f}' stroke='#ddd'/><text x='{3:.1f}' "
          "y='{4:.1f}' text-anchor='end'>{5:g}</text>\n",
          pn.x0, pn.py(v), pn.x0 + pn.w, pn.x0 - 6, pn.py(v) + 4, v);
    s += fmt::format("<text x='{:.1f}' y='{:.1f}' text-anchor='middle'>inclination angle θ (deg)</text>\n",
                     pn.x0 + pn.w / 2, pn.y0 + pn.h + 40);
    s += fmt::format(
        "<text transform='translate({:.1f},{:.1f}) rotate(-90)' text-anchor='middle'>{}</text>\n", pn.x0 - 55,
        pn.y0 + pn.h / 2, panel == 0 ? "⟨⟨w_p⟩⟩ (mm/s)" : "r_acc = ⟨⟨w_p⟩⟩ / ⟨⟨w_p⟩⟩(90°)");
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const char* color = report::color(g);
      std::string line;
      std::string marks;
      for (const auto& p : pts) {
        if (series_of(p) != groups[g]) continue;
        auto v = value(p);
        if (!v) continue;
        const double x = pn.px(p.angle_deg), y = pn.py(v->first);
        line += fmt::format("{:.1f},{:.1f} ", x, y);
        for (double r : replica_values(p))
          marks += fmt::format(
              "<circle class='replica' cx='{:.1f}' cy='{:.1f}' r='2.5' fill='{}' fill-opacity='0.3'/>\n",
              x + 7, pn.py(r), color);
        if (v->second > 0)
          marks += fmt::format(
              "<g class='errorbar' stroke='{3}' stroke-width='1.5'><line x1='{0:.1f}' y1='{1:.1f}' "
              "x2='{0:.1f}' "
              "y2='{2:.1f}'/><line x1='{4:.1f}' y1='{1:.1f}' x2='{5:.1f}' y2='{1:.1f}'/>"
              "<line x1='{4:.1f}' y1='{2:.1f}' x2='{5:.1f}' y2='{2:.1f}'/></g>\n",
              x, pn.py(v->first - v->second), pn.py(v->first + v->second), color, x - 5, x + 5);
        marks += marker(report::marker_kind(g), x, y, color) + "\n";
      }
      if (!line.empty())
        s += fmt::format(
            "<polyline class='group' data-group='{}' points='{}' fill='none' stroke='{}' "
            "stroke-width='1.5'/>\n",
            xml_escape(groups[g]), line, color);
      s += marks;
      if (panel == 1)
        s += fmt::format("{}<text x='{:.1f}' y='{:.1f}'>{}</text>\n",
                         marker(report::marker_kind(g), pn.x0 + 18, pn.y0 + 18 + 18.0 * g, color), pn.x0 + 28,
                         pn.y0 + 22 + 18.0 * g, xml_escape(groups[g]));
    }
    if (paper) {
      for (const auto& v : *paper) {
        if (v.quantity != quantity) continue;
        const double y = pn.py(v.value * scale);
        const char* color = paper_color(v);
        if (v.angle_deg)
          s += fmt::format("<g class='paper' data-group='{}'>{}</g>\n", xml_escape(v.group),
                           marker("diamond", pn.px(*v.angle_deg), y, color, true));
        else
          s += fmt::format(
              "<line class='paper' data-group='{}' x1='{:.1f}' y1='{:.1f}' x2='{:.1f}' y2='{:.1f}' "
              "stroke='{}' "
              "stroke-width='1.5' stroke-dasharray='5,3'/>\n",
              xml_escape(v.group), pn.px(kPeakFrom), y, pn.px(kPeakTo), y, color);
      }
      if (panel == 1) {
        const double ly = pn.y0 + 22 + 18.0 * static_cast<double>(groups.size());
        s += fmt::format(
            "{}<text x='{:.1f}' y='{:.1f}'>Zeng et al. 2021 (stated values; dashed: peak, angle not "
            "stated)</text>\n",
            marker("diamond", pn.x0 + 18, ly - 4, "#333", true), pn.x0 + 28, ly);
      }
    }
  }
  if (std::any_of(pts.begin(), pts.end(), [](const CurvePoint& p) { return p.n_replicas > 1; }))
    s +=
        "<text x='500' y='436' text-anchor='middle' font-size='11' fill='#555'>faint dots: replicas (seeds); "
        "error bars: their standard error of the mean</text>\n";
  s += "</svg>\n";
  return s;
}

std::string format_cases(const std::vector<CaseState>& cases) {
  std::string s = fmt::format("{:<12} {:<12} {:<16} {:>6} {:<12} {:>8}  {}\n", "study", "group", "case",
                              "angle", "status", "failures", "last error");
  for (const auto& c : cases)
    s += fmt::format("{:<12} {:<12} {:<16} {:>6g} {:<12} {:>8}  {}\n", c.study, c.group, c.id, c.angle_deg,
                     to_string(c.status), c.failures, c.status == CaseStatus::kDone ? "" : c.last_error);
  return s;
}

}  // namespace boycott::driver
