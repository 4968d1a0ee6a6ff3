#include "driver/report/curve.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "driver/report/report_util.hpp"

namespace boycott::driver {

using report::ticks;

std::string format_curve(const std::vector<CurvePoint>& pts, ListingFormat f) {
  std::string s;
  auto opt = [](const std::optional<double>& v) { return v ? fmt::format("{:.6g}", *v) : std::string(); };
  auto opt9 = [](const std::optional<double>& v) { return v ? fmt::format("{:.9g}", *v) : std::string(); };
  auto opt_json = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  if (f == ListingFormat::kCsv) {
    s = "group,angle_deg,mean_settling_velocity_m_s,error_m_s,error_basis,stderr_m_s,n_replicas,"
        "between_replica_stderr_m_s,mean_within_run_stderr_m_s,r_acc,r_acc_err,error_method,n_particles,"
        "average_from_s,end_s,case_id,setting\n";
    for (const auto& p : pts)
      s += fmt::format(
          "{},{:g},{:.9g},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", report::csv_field(p.group),
          p.angle_deg, p.w_m_s, opt9(p.error.error_m_s), report::csv_field(p.error.basis), opt9(p.w_err_m_s),
          p.n_replicas, opt9(p.between_replica_stderr_m_s), opt9(p.mean_within_run_stderr_m_s), opt(p.r_acc),
          opt(p.r_acc_err), p.error_method, p.n_particles ? std::to_string(*p.n_particles) : std::string(),
          opt9(p.average_from_s), opt9(p.end_s), p.case_id, report::csv_field(p.setting));
  } else if (f == ListingFormat::kJson) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& p : pts) {
      nlohmann::json e = {{"group", p.group},
                          {"angle_deg", p.angle_deg},
                          {"mean_settling_velocity_m_s", p.w_m_s},
                          {"case_id", p.case_id},
                          {"setting", p.setting}};
      e["error_m_s"] = opt_json(p.error.error_m_s);
      e["error_basis"] = p.error.basis;
      e["stderr_m_s"] = opt_json(p.w_err_m_s);
      e["n_replicas"] = p.n_replicas;
      e["between_replica_stderr_m_s"] = opt_json(p.between_replica_stderr_m_s);
      e["mean_within_run_stderr_m_s"] = opt_json(p.mean_within_run_stderr_m_s);
      e["error_method"] = p.error_method;
      e["r_acc"] = opt_json(p.r_acc);
      e["r_acc_err"] = opt_json(p.r_acc_err);
      e["n_particles"] = p.n_particles ? nlohmann::json(*p.n_particles) : nlohmann::json(nullptr);
      e["average_from_s"] = opt_json(p.average_from_s);
      e["end_s"] = opt_json(p.end_s);
      e["replica_case_ids"] = p.replica_case_ids;
      e["replica_mean_settling_velocities_m_s"] = p.replica_w_m_s;
      j.push_back(e);
    }
    s = j.dump(2) + "\n";
  } else if (pts.empty()) {
    s = "(no finished cases)\n";
  } else {
    // A missing error is "n/a", never a zero that reads as an exact value. The error after +-
    // covers ~68 % (error_m_s, its basis in the last columns); "between" is the replicas' plain
    // sd/sqrt(n), "within" the mean of the runs' own plain errors, one run's: honest run errors
    // give between x sqrt(n) ~ within.
    auto mm = [](const std::optional<double>& v) { return v ? fmt::format("{:.4f}", *v * 1e3) : "n/a"; };
    report::TextTable t({"group", "angle", "<<w_p>> +- 68 % (mm/s)", "n", "between (mm/s)",
                         "within, 1 run (mm/s)", "r_acc +- 68 %", "error basis", "setting"},
                        {false, true, true, true, true, true, true, false, false});
    for (const auto& p : pts) {
      const std::string r = p.r_acc ? fmt::format("{:.3f} +- {}", *p.r_acc,
                                                  p.r_acc_err ? fmt::format("{:.3f}", *p.r_acc_err) : "n/a")
                                    : "-";
      t.add({p.group, fmt::format("{:g}", p.angle_deg),
             fmt::format("{:.4f} +- {}", p.w_m_s * 1e3, mm(p.error.error_m_s)), std::to_string(p.n_replicas),
             p.n_replicas >= 2 ? mm(p.between_replica_stderr_m_s) : "-", mm(p.mean_within_run_stderr_m_s), r,
             p.error.basis.empty() ? "-" : p.error.basis, p.setting});
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

/// A point's value on a panel and its error (0: unknown, no bar); panel 0: <<w_p>> in mm/s,
/// panel 1: r_acc (none where the group has no 90 deg point).
std::optional<std::pair<double, double>> panel_value(const CurvePoint& p, int panel) {
  if (panel == 0) return std::pair{p.w_m_s * 1e3, p.error.error_m_s.value_or(0.0) * 1e3};
  if (!p.r_acc) return std::nullopt;
  return std::pair{*p.r_acc, p.r_acc_err.value_or(0.0)};
}

/// Each replica's value on a panel: its <<w_p>>, or its ratio to the point's 90 deg mean.
std::vector<double> replica_values(const CurvePoint& p, int panel) {
  std::vector<double> v;
  if (p.n_replicas < 2) return v;
  for (double w : p.replica_w_m_s) {
    if (panel == 0)
      v.push_back(w * 1e3);
    else if (p.r_acc && p.w_m_s != 0.0)
      v.push_back(w * *p.r_acc / p.w_m_s);
  }
  return v;
}

/// The two panels of `query curve --plot`, their legend and caption.
class CurveFigure {
 public:
  CurveFigure(const std::vector<CurvePoint>& pts, const std::vector<PaperValue>* paper,
              const std::vector<PeakRow>* peaks)
      : pts_(pts), peaks_(peaks) {
    for (const auto& p : pts)
      if (std::find(series_.begin(), series_.end(), series_of(p)) == series_.end())
        series_.push_back(series_of(p));
    // The paper's values of the groups this study has; none of another group's.
    if (paper)
      for (const auto& v : *paper)
        if (std::any_of(pts.begin(), pts.end(), [&](const CurvePoint& p) { return p.group == v.group; })) {
          overlay_.push_back(v);
          if (paper_groups_.find(v.group) == std::string::npos)
            paper_groups_ += (paper_groups_.empty() ? "" : ", ") + v.group;
        }
    lay_out_legend();
  }

  /// The page's height (px): the panels, one legend row per kLegendRow, the caption.
  double height() const { return 470.0 + kLegendRow * static_cast<double>(legend_rows_.size() - 1); }

  void draw(plot::Canvas& c, const std::string& title) const {
    c.text(500, 22, title, plot::Anchor::kMiddle, 15);
    for (int panel = 0; panel < 2; ++panel) draw_panel(c, panel);
    draw_legend(c);
    c.text(500, height() - 8.0, caption(), plot::Anchor::kMiddle, 11, "#555");
  }

 private:
  /// A paper value takes the colour of the first series of its group, grey when the study has none.
  const char* paper_color(const PaperValue& v) const {
    for (std::size_t g = 0; g < series_.size(); ++g)
      for (const auto& p : pts_)
        if (series_of(p) == series_[g] && p.group == v.group) return report::color(g);
    return "#777";
  }

  /// The panel's box and data range: every value with its bar, replica and paper value inside.
  Panel layout(int panel) const {
    const char* quantity = panel == 0 ? "mean_settling_velocity_m_s" : "r_acc";
    const double scale = panel == 0 ? 1e3 : 1.0;
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& p : pts_) {
      if (auto v = panel_value(p, panel)) {
        lo = std::min(lo, v->first - v->second);
        hi = std::max(hi, v->first + v->second);
      }
      for (const auto& box : peak_boxes(panel)) lo = std::min(lo, box.v_lo), hi = std::max(hi, box.v_hi);
      for (double r : replica_values(p, panel)) lo = std::min(lo, r), hi = std::max(hi, r);
    }
    for (const auto& v : overlay_)
      if (v.quantity == quantity) lo = std::min(lo, v.value * scale), hi = std::max(hi, v.value * scale);
    if (!std::isfinite(lo)) lo = 0, hi = 1;
    if (panel == 1) lo = std::min(lo, 1.0), hi = std::max(hi, 1.0);
    if (hi - lo < 1e-12) lo -= 0.5, hi += 0.5;
    const double pad = 0.08 * (hi - lo);
    return Panel{80.0 + panel * 490.0, 50.0, 400.0, 320.0, lo - pad, hi + pad};
  }

  void draw_axes(plot::Canvas& c, const Panel& pn, int panel) const {
    using plot::Anchor;
    for (double v : ticks(pn.vmin, pn.vmax)) {
      c.line(pn.x0, pn.py(v), pn.x0 + pn.w, pn.py(v), "#ddd");
      c.text(pn.x0 - 6, pn.py(v) + 4, fmt::format("{:g}", v), Anchor::kEnd);
    }
    c.stroke_rect(pn.x0, pn.y0, pn.w, pn.h, "#000", "panel");
    for (double a = 15; a <= 90; a += 15) {
      c.line(pn.px(a), pn.y0 + pn.h, pn.px(a), pn.y0 + pn.h - 5, "#000");
      c.text(pn.px(a), pn.y0 + pn.h + 18, fmt::format("{:g}", a), Anchor::kMiddle);
    }
    c.text(pn.x0 + pn.w / 2, pn.y0 + pn.h + 40, "inclination angle θ (deg)", Anchor::kMiddle);
    c.label(pn.x0 - 55, pn.y0 + pn.h / 2,
            panel == 0 ? "⟨⟨w_{p}⟩⟩ (mm/s)" : "r_{acc} = ⟨⟨w_{p}⟩⟩ / ⟨⟨w_{p}⟩⟩(90°)", Anchor::kMiddle, 13,
            true);
  }

  /// One series: its line, each point's replicas, error bar and marker.
  void draw_series(plot::Canvas& c, const Panel& pn, int panel, std::size_t g) const {
    const char* color = report::color(g);
    std::vector<std::pair<double, double>> line;
    for (const auto& p : pts_)
      if (auto v = series_of(p) == series_[g] ? panel_value(p, panel) : std::nullopt)
        line.emplace_back(pn.px(p.angle_deg), pn.py(v->first));
    c.polyline(line, color, 1.5, line.empty() ? "" : "group");
    for (const auto& p : pts_) {
      if (series_of(p) != series_[g]) continue;
      auto v = panel_value(p, panel);
      if (!v) continue;
      const double x = pn.px(p.angle_deg), y = pn.py(v->first);
      for (double r : replica_values(p, panel)) c.circle(x + 7, pn.py(r), 2.5, color, 0.3, "replica");
      if (v->second > 0) {
        const double y_lo = pn.py(v->first - v->second), y_hi = pn.py(v->first + v->second);
        c.line(x, y_lo, x, y_hi, color, 1.5, {}, "errorbar");
        c.line(x - 5, y_lo, x + 5, y_lo, color, 1.5);
        c.line(x - 5, y_hi, x + 5, y_hi, color, 1.5);
      }
      // A point without an error is drawn open (named in the caption), not as one with a tiny bar.
      const bool no_error = panel == 0 ? !p.error.error_m_s : !p.r_acc_err;
      c.marker(report::marker_kind(g), x, y, color, no_error);
    }
  }

  /// Each curve's peak on a panel: its angle and value with their 68 % intervals, its colour.
  struct PeakBox {
    double x, x_lo, x_hi, v, v_lo, v_hi;
    const char* color;
  };
  std::vector<PeakBox> peak_boxes(int panel) const {
    std::vector<PeakBox> out;
    if (!peaks_) return out;
    for (const auto& r : *peaks_) {
      const std::string name = r.setting.empty() ? r.group : r.group + " " + r.setting;
      const auto g = std::find(series_.begin(), series_.end(), name);
      if (g == series_.end() || !r.peak.bracketed()) continue;
      const char* color = report::color(static_cast<std::size_t>(g - series_.begin()));
      if (panel == 0) {
        const double v = r.w_m_s * 1e3, e = r.peak.y_error() * 1e3;
        out.push_back({r.peak.x, r.peak.x_low, r.peak.x_high, v, v - e, v + e, color});
      } else if (r.r_acc) {
        const double e = r.r_acc_err.value_or(0.0);
        out.push_back({r.peak.x, r.peak.x_low, r.peak.x_high, *r.r_acc, *r.r_acc - e, *r.r_acc + e, color});
      }
    }
    return out;
  }

  void draw_peaks(plot::Canvas& c, const Panel& pn, int panel) const {
    for (const auto& b : peak_boxes(panel)) {
      const double x0 = pn.px(b.x_lo), x1 = pn.px(b.x_hi), y0 = pn.py(b.v_hi), y1 = pn.py(b.v_lo);
      const std::vector<double> dash{4, 3};
      c.line(x0, y0, x1, y0, b.color, 1.2, dash, "peak");
      c.line(x0, y1, x1, y1, b.color, 1.2, dash);
      c.line(x0, y0, x0, y1, b.color, 1.2, dash);
      c.line(x1, y0, x1, y1, b.color, 1.2, dash);
      const double x = pn.px(b.x), y = pn.py(b.v);
      c.line(x - 6, y - 6, x + 6, y + 6, b.color, 1.5);
      c.line(x - 6, y + 6, x + 6, y - 6, b.color, 1.5);
    }
  }

  void draw_panel(plot::Canvas& c, int panel) const {
    const Panel pn = layout(panel);
    draw_axes(c, pn, panel);
    for (std::size_t g = 0; g < series_.size(); ++g) draw_series(c, pn, panel, g);
    draw_peaks(c, pn, panel);
    const char* quantity = panel == 0 ? "mean_settling_velocity_m_s" : "r_acc";
    const double scale = panel == 0 ? 1e3 : 1.0;
    for (const auto& v : overlay_) {
      if (v.quantity != quantity) continue;
      const double y = pn.py(v.value * scale);
      const char* color = paper_color(v);
      if (v.angle_deg) {
        c.marker("diamond", pn.px(*v.angle_deg), y, color, true);
        c.tally("paper");
      } else {
        c.line(pn.px(kPeakFrom), y, pn.px(kPeakTo), y, color, 1.5, {5, 3}, "paper");
      }
    }
  }

  /// A legend entry: its marker kind ("paper": the paper's diamond), colour index and text.
  struct LegendEntry {
    std::string marker;
    std::size_t color = 0;
    std::string text;
    double width = 0.0;  ///< marker, text and the gap after it (px)
  };
  static constexpr double kLegendRow = 18.0;     ///< px between legend rows
  static constexpr double kLegendWidth = 960.0;  ///< px a row may fill (the page less margins)

  /// The entries in rows under the panels, each row as wide as fits the page: a study with many
  /// groups, or the paper's long entry, wraps instead of running off the page.
  void lay_out_legend() {
    std::vector<LegendEntry> entries;
    for (std::size_t g = 0; g < series_.size(); ++g)
      entries.push_back({report::marker_kind(g), g, series_[g]});
    if (!overlay_.empty())
      entries.push_back({"paper", 0,
                         "Zeng et al. 2021, group " + paper_groups_ +
                             ": stated values (dashed: a peak whose angle is not stated)"});
    legend_rows_.assign(1, {});
    double used = 0.0;
    for (auto& e : entries) {
      e.width = 16.0 + plot::text_width(e.text) + 24.0;
      if (!legend_rows_.back().empty() && used + e.width - 24.0 > kLegendWidth) {
        legend_rows_.emplace_back();
        used = 0.0;
      }
      used += e.width;
      legend_rows_.back().push_back(std::move(e));
    }
  }

  /// The legend: rows under the panels, each centred, where they cover no data.
  void draw_legend(plot::Canvas& c) const {
    double y = 436.0;
    for (const auto& row : legend_rows_) {
      double width = 0.0;
      for (const auto& e : row) width += e.width;
      double x = 500.0 - (width - 24.0) / 2.0;
      for (const auto& e : row) {
        const bool is_paper = e.marker == "paper";
        c.marker(is_paper ? "diamond" : e.marker.c_str(), x + 5, y - 4,
                 is_paper ? "#333" : report::color(e.color), is_paper);
        c.text(x + 16, y, e.text, plot::Anchor::kStart, 13, "#000", false, "legend");
        x += e.width;
      }
      y += kLegendRow;
    }
  }

  std::string caption() const {
    const bool any_without_error = std::any_of(pts_.begin(), pts_.end(), [](const CurvePoint& p) {
      return !p.error.error_m_s || (p.r_acc && !p.r_acc_err);
    });
    return std::string("error bars: the interval that covers the mean ~68 % of the time (Student's t)") +
           (std::any_of(pts_.begin(), pts_.end(), [](const CurvePoint& p) { return p.n_replicas > 1; })
                ? "; faint dots: replicas (seeds)"
                : "") +
           (any_without_error ? "; open markers: no error available" : "") +
           (peaks_ && !peak_boxes(0).empty() ? "; dashed boxes: each curve's peak, 68 % in angle and value"
                                             : "");
  }

  const std::vector<CurvePoint>& pts_;
  const std::vector<PeakRow>* peaks_;
  std::vector<std::string> series_;
  std::vector<PaperValue> overlay_;
  std::string paper_groups_;
  std::vector<std::vector<LegendEntry>> legend_rows_;
};

}  // namespace

plot::Plot curve_plot(const std::vector<CurvePoint>& pts, const std::string& title,
                      const std::vector<PaperValue>* paper, plot::Format format,
                      const std::vector<PeakRow>* peaks) {
  const CurveFigure figure(pts, paper, peaks);
  return plot::render(1000, figure.height(), format, [&](plot::Canvas& c) { figure.draw(c, title); });
}

std::string format_cases(const std::vector<CaseState>& cases, ListingFormat f) {
  report::TextTable t({"study", "group", "case", "angle_deg", "status", "failures", "last_error"},
                      {false, false, false, true, false, true, false});
  for (const auto& c : cases)
    t.add({c.study, c.group, c.id, fmt::format("{:g}", c.angle_deg), to_string(c.status),
           std::to_string(c.failures), c.status == CaseStatus::kDone ? "" : c.last_error});
  if (f == ListingFormat::kCsv) return t.csv();
  if (f == ListingFormat::kJson) return t.json().dump(2) + "\n";
  return t.str();
}

}  // namespace boycott::driver
