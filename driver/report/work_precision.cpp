#include "driver/report/work_precision.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/key_docs.hpp"
#include "driver/report/curve_query.hpp"
#include "driver/report/report_util.hpp"
#include "stats/point_error.hpp"
#include "stats/relative_difference.hpp"

namespace boycott::driver {

namespace {

constexpr const char* kAngleKey = "gravity.angle_deg";

std::vector<SweptValue> setting_of(Database& db, const std::string& case_id) {
  auto v = case_swept_values(db, case_id);
  std::erase_if(v, [](const SweptValue& x) { return x.key == kAngleKey; });
  return v;
}

/// One (group, setting, angle) of the study with its finished replicas averaged: a curve point
/// (driver/report/curve_query.hpp), so that replicas count once, as their mean with the standard
/// error of that mean, and the cost of one of its runs.
struct Measured {
  std::string group, case_id;  ///< case_id: the first replica's
  double angle_deg = 0;
  double w_m_s = 0, w_err_m_s = 0;  ///< NaN error when a single run gave none
  int n_replicas = 1;
  stats::PointError error;                     ///< the point's covering error (the curve's)
  std::optional<double> wall_time_s;           ///< mean over the replicas that recorded one
  std::optional<std::int64_t> particle_steps;  ///< likewise
};

std::vector<Measured> measured_points(Database& db, const std::string& study) {
  std::map<std::string, SettlingResult> by_id;
  for (auto& r : settling_results(db, study)) by_id.try_emplace(r.case_id, std::move(r));
  std::vector<Measured> out;
  for (const auto& p : query_curve(db, study)) {
    Measured m{p.group,      p.case_id, p.angle_deg, p.w_m_s, p.w_err_m_s.value_or(std::nan("")),
               p.n_replicas, p.error,   {},          {}};
    double wall = 0.0, steps = 0.0;
    int n_wall = 0, n_steps = 0;
    for (const auto& id : p.replica_case_ids) {
      const auto it = by_id.find(id);
      if (it == by_id.end()) continue;
      if (it->second.wall_time_s) wall += *it->second.wall_time_s, ++n_wall;
      if (it->second.particle_steps) steps += static_cast<double>(*it->second.particle_steps), ++n_steps;
    }
    if (n_wall) m.wall_time_s = wall / n_wall;
    if (n_steps) m.particle_steps = std::llround(steps / n_steps);
    out.push_back(std::move(m));
  }
  return out;
}

const Measured& reference_at(const std::vector<Measured>& refs, const std::string& ref_group, Database& db,
                             const Measured& run) {
  std::vector<const Measured*> found;
  for (const auto& r : refs)
    if (r.angle_deg == run.angle_deg) found.push_back(&r);
  if (found.empty())
    throw InputError(fmt::format(
        "no finished case of reference group '{}' at {} = {:g} (needed by group '{}' case {}): run the "
        "reference at that angle, or name another reference group with --reference",
        ref_group, kAngleKey, run.angle_deg, run.group, run.case_id));
  if (found.size() > 1) {
    std::string names;
    for (const auto* r : found)
      names += fmt::format("{}{} ({})", names.empty() ? "" : ", ", r->case_id,
                           report::join_values(setting_of(db, r->case_id)));
    throw InputError(fmt::format(
        "reference group '{}' has {} finished cases at {} = {:g} that differ in more than their seed: {}; "
        "a work-precision reference needs one setting per angle (its replicas are averaged)",
        ref_group, found.size(), kAngleKey, run.angle_deg, names));
  }
  if (found[0]->w_m_s == 0.0)
    throw InputError(
        fmt::format("reference case {} at {} = {:g} has <<w_p>> = 0: the relative error is undefined",
                    found[0]->case_id, kAngleKey, run.angle_deg));
  return *found[0];
}

std::string percent_pm(double e, double u) {
  // No uncertainty where a run gave no error of its own (a window too short to estimate one).
  if (std::isnan(u)) return report::percent(e) + " +- n/a";
  const double up = u * 100.0;
  return fmt::format("{} +- {}", report::percent(e),
                     up >= 0.01 || up == 0.0 ? fmt::format("{:.2f} %", up) : fmt::format("{:.2g} %", up));
}

}  // namespace

WorkPrecision query_work_precision(Database& db, const std::string& study,
                                   const std::string& reference_group) {
  require_study(db, study);
  const std::vector<std::string> groups = study_groups(db, study);  // study order
  if (std::find(groups.begin(), groups.end(), reference_group) == groups.end()) {
    std::string names;
    for (const auto& g : groups) names += (names.empty() ? "" : ", ") + g;
    throw InputError(
        fmt::format("study '{}' has no group '{}' (its groups: {}): name the reference group with "
                    "--reference",
                    study, reference_group, names.empty() ? "none" : names));
  }

  std::vector<Measured> refs, runs;
  for (auto& m : measured_points(db, study))
    (m.group == reference_group ? refs : runs).push_back(std::move(m));

  WorkPrecision wp{study, reference_group, {}, {}};
  for (const auto& run : runs) {
    const auto& ref = reference_at(refs, reference_group, db, run);
    WorkPrecisionRow row;
    row.group = run.group;
    row.case_id = run.case_id;
    row.setting = setting_of(db, run.case_id);
    row.angle_deg = run.angle_deg;
    row.wall_time_s = run.wall_time_s;
    row.particle_steps = run.particle_steps;
    row.w_m_s = run.w_m_s;
    row.w_err_m_s = run.w_err_m_s;
    row.n_replicas = run.n_replicas;
    row.ref_case_id = ref.case_id;
    row.ref_n_replicas = ref.n_replicas;
    row.w_ref_m_s = ref.w_m_s;
    row.w_ref_err_m_s = ref.w_err_m_s;
    const stats::RelativeDifference e =
        stats::relative_difference(run.w_m_s, run.w_err_m_s, ref.w_m_s, ref.w_err_m_s);
    row.rel_error_w = e.value;
    row.rel_error_w_unc = e.stderr_of_value;
    // w / w_ref - 1 has the error of the ratio w / w_ref.
    row.rel_error_w_err = stats::ratio_error(run.w_m_s, run.error, ref.w_m_s, ref.error);
    wp.rows.push_back(std::move(row));
    if (std::none_of(wp.references.begin(), wp.references.end(),
                     [&](const ReferenceRun& r) { return r.case_id == ref.case_id; }))
      wp.references.push_back(
          {ref.case_id, ref.angle_deg, ref.w_m_s, ref.w_err_m_s, ref.wall_time_s, ref.n_replicas});
  }

  // r_acc against the reference's r_acc: the quantity the paper reports, whose error can be far
  // smaller than that of <<w_p>> when a setting shifts all angles alike.
  for (auto& row : wp.rows) {
    if (row.angle_deg == 90.0) continue;
    const WorkPrecisionRow* v90 = nullptr;
    for (const auto& q : wp.rows)
      if (q.group == row.group && q.angle_deg == 90.0 && q.setting == row.setting) v90 = &q;
    if (!v90 || v90->w_m_s == 0.0) continue;
    // R = (w / w90) / (wr / wr90); every reference w is non-zero (checked above).
    const stats::RelativeDifference e =
        stats::ratio_of_ratios_difference(row.w_m_s, row.w_err_m_s, v90->w_m_s, v90->w_err_m_s, row.w_ref_m_s,
                                          row.w_ref_err_m_s, v90->w_ref_m_s, v90->w_ref_err_m_s);
    row.rel_error_r_acc = e.value;
    row.rel_error_r_acc_unc = e.stderr_of_value;
  }

  std::map<std::string, std::size_t> order;
  for (std::size_t i = 0; i < groups.size(); ++i) order[groups[i]] = i;
  std::stable_sort(wp.rows.begin(), wp.rows.end(), [&](const WorkPrecisionRow& a, const WorkPrecisionRow& b) {
    if (a.group != b.group) return order[a.group] < order[b.group];
    // Cases without a recorded wall time last.
    if (a.wall_time_s.has_value() != b.wall_time_s.has_value()) return a.wall_time_s.has_value();
    if (a.wall_time_s && *a.wall_time_s != *b.wall_time_s) return *a.wall_time_s < *b.wall_time_s;
    return a.angle_deg < b.angle_deg;
  });
  std::sort(wp.references.begin(), wp.references.end(),
            [](const ReferenceRun& a, const ReferenceRun& b) { return a.angle_deg < b.angle_deg; });
  return wp;
}

std::string format_work_precision(const WorkPrecision& wp, ListingFormat f) {
  if (f == ListingFormat::kJson) {
    nlohmann::json refs = nlohmann::json::array(), rows = nlohmann::json::array();
    for (const auto& r : wp.references)
      refs.push_back({{"case_id", r.case_id},
                      {"angle_deg", r.angle_deg},
                      {"mean_settling_velocity_m_s", r.w_m_s},
                      {"stderr_m_s", r.w_err_m_s},
                      {"wall_time_s", report::json_number(r.wall_time_s)},
                      {"n_replicas", r.n_replicas}});
    for (const auto& r : wp.rows) {
      nlohmann::json setting = nlohmann::json::object();
      for (const auto& v : r.setting) setting[v.key] = report::value_json(v);
      rows.push_back(
          {{"group", r.group},
           {"setting", setting},
           {"angle_deg", r.angle_deg},
           {"wall_time_s", report::json_number(r.wall_time_s)},
           {"particle_steps", r.particle_steps ? nlohmann::json(*r.particle_steps) : nlohmann::json(nullptr)},
           {"mean_settling_velocity_m_s", r.w_m_s},
           {"stderr_m_s", r.w_err_m_s},
           {"reference_m_s", r.w_ref_m_s},
           {"reference_stderr_m_s", r.w_ref_err_m_s},
           {"rel_error_w", r.rel_error_w},
           {"rel_error_w_uncertainty", r.rel_error_w_unc},
           {"rel_error_w_error", report::json_number(r.rel_error_w_err)},
           {"rel_error_r_acc", report::json_number(r.rel_error_r_acc)},
           {"rel_error_r_acc_uncertainty", report::json_number(r.rel_error_r_acc_unc)},
           {"case_id", r.case_id},
           {"reference_case_id", r.ref_case_id},
           {"n_replicas", r.n_replicas},
           {"reference_n_replicas", r.ref_n_replicas}});
    }
    const nlohmann::json j = {
        {"study", wp.study}, {"reference_group", wp.reference_group}, {"references", refs}, {"rows", rows}};
    return j.dump(2) + "\n";
  }
  if (f == ListingFormat::kCsv) {
    std::string s =
        "group,setting,angle_deg,wall_time_s,particle_steps,mean_settling_velocity_m_s,stderr_m_s,reference_"
        "m_s,"
        "reference_stderr_m_s,rel_error_w,rel_error_w_uncertainty,rel_error_w_error,rel_error_r_acc,"
        "rel_error_r_acc_uncertainty,"
        "case_id,reference_case_id,n_replicas,reference_n_replicas\n";
    for (const auto& r : wp.rows)
      s += fmt::format(
          "{},{},{:g},{},{},{:.9g},{},{:.9g},{},{:.9g},{},{},{},{},{},{},{},{}\n", report::csv_field(r.group),
          report::csv_field(report::join_values(r.setting)), r.angle_deg, report::csv_number(r.wall_time_s),
          r.particle_steps ? std::to_string(*r.particle_steps) : "", r.w_m_s, report::csv_number(r.w_err_m_s),
          r.w_ref_m_s, report::csv_number(r.w_ref_err_m_s), r.rel_error_w,
          report::csv_number(r.rel_error_w_unc), report::csv_number(r.rel_error_w_err),
          report::csv_number(r.rel_error_r_acc), report::csv_number(r.rel_error_r_acc_unc), r.case_id,
          r.ref_case_id, r.n_replicas, r.ref_n_replicas);
    return s;
  }
  if (wp.rows.empty())
    return fmt::format("(no finished cases outside the reference group '{}')\n", wp.reference_group);
  report::TextTable t({"group", "setting", "angle", "runs", "wall (s)", "particle steps", "<<w_p>> (mm/s)",
                       "ref (mm/s)", "error <<w_p>> +- 68 %", "error r_acc +- s.e."},
                      {false, false, true, true, true, true, true, true, true, true});
  for (const auto& r : wp.rows)
    t.add({r.group, report::join_values(r.setting), fmt::format("{:g}", r.angle_deg),
           std::to_string(r.n_replicas), r.wall_time_s ? report::seconds(*r.wall_time_s) : "-",
           r.particle_steps ? std::to_string(*r.particle_steps) : "-", fmt::format("{:.4f}", r.w_m_s * 1e3),
           fmt::format("{:.4f}", r.w_ref_m_s * 1e3),
           percent_pm(r.rel_error_w, r.rel_error_w_err.value_or(std::nan(""))),
           r.rel_error_r_acc ? percent_pm(*r.rel_error_r_acc, *r.rel_error_r_acc_unc) : "-"});
  std::string s = t.str();
  for (const auto& r : wp.references)
    s += fmt::format("reference '{}' at {:g} deg: <<w_p>> {:.4f} +- {} mm/s, wall {} s, case {}{}\n",
                     wp.reference_group, r.angle_deg, r.w_m_s * 1e3,
                     std::isnan(r.w_err_m_s) ? std::string("n/a") : fmt::format("{:.4f}", r.w_err_m_s * 1e3),
                     r.wall_time_s ? report::seconds(*r.wall_time_s) : "-", r.case_id,
                     r.n_replicas > 1
                         ? fmt::format(" and {} more replicas (mean and its standard error; wall: one run's)",
                                       r.n_replicas - 1)
                         : "");
  return s;
}

namespace {

/// The order of a group's varied setting: numbers as numbers, key by key.
bool setting_before(const std::vector<SweptValue>& a, const std::vector<SweptValue>& b) {
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    if (a[i].key != b[i].key) return a[i].key < b[i].key;
    if (a[i].value_num && b[i].value_num) {
      if (*a[i].value_num != *b[i].value_num) return *a[i].value_num < *b[i].value_num;
    } else if (a[i].value != b[i].value) {
      return a[i].value < b[i].value;
    }
  }
  return a.size() < b.size();
}

/// A value in its key's unit for people: times in s, ms or µs ("50 µs"), other units appended
/// ("0.01 m"), pure numbers and lists as they are.
std::string value_with_unit(const SweptValue& v) {
  const auto doc = key_doc(v.key);
  const std::string unit = doc ? doc->unit : "";
  if (!v.value_num || unit.empty() || unit == "-") return v.display();
  const double x = *v.value_num;
  if (unit == "s" && x != 0.0 && std::abs(x) < 1.0)
    return std::abs(x) < 1e-3 ? fmt::format("{:g} µs", x * 1e6) : fmt::format("{:g} ms", x * 1e3);
  return fmt::format("{} {}", v.display(), unit);
}

/// A point's label: each varied key's last part and its value ("dt_dem 50 µs", "cells [10, 3, 10]").
std::string setting_label(const std::vector<SweptValue>& v) {
  std::string s;
  for (const auto& x : v) {
    const auto dot = x.key.rfind('.');
    s += (s.empty() ? "" : "; ") + x.key.substr(dot == std::string::npos ? 0 : dot + 1) + " " +
         value_with_unit(x);
  }
  return s;
}

/// Only positive wall times have a place on a log axis.
bool plotted(const WorkPrecisionRow& r) {
  return r.wall_time_s && *r.wall_time_s > 0;
}

/// `query work-precision --plot`: one panel per angle of the signed relative error (%) against
/// wall time (log), each group a line through its settings, the reference at 0 and its runs' wall
/// time as a dashed line.
class WorkPrecisionFigure {
 public:
  static constexpr double w = 400, h = 360, y0 = 60, gap = 90;

  explicit WorkPrecisionFigure(const WorkPrecision& wp) : wp_(wp) {
    for (const auto& r : wp.rows) {
      if (std::find(groups_.begin(), groups_.end(), r.group) == groups_.end()) groups_.push_back(r.group);
      if (std::find(angles_.begin(), angles_.end(), r.angle_deg) == angles_.end())
        angles_.push_back(r.angle_deg);
    }
    std::sort(angles_.begin(), angles_.end());
    if (angles_.empty()) angles_.push_back(90.0);
    set_ranges();
  }

  double width() const { return 90 + angles_.size() * (w + gap) + 170; }
  static constexpr double height() { return 520; }

  void draw(plot::Canvas& c, const std::string& title) const {
    c.text((90 + angles_.size() * (w + gap) - gap) / 2 + 45, 24, title, plot::Anchor::kMiddle, 15);
    for (std::size_t a = 0; a < angles_.size(); ++a) draw_panel(c, a);
    draw_legend(c);
  }

 private:
  static double percent_of(double rel) { return rel * 100.0; }
  static double bar_of(const WorkPrecisionRow& r) { return r.rel_error_w_err ? *r.rel_error_w_err : 0.0; }

  /// x: the points' and the references' wall times; y: the points with their bars and 0 (the
  /// reference), the same in every panel so that the angles compare at a glance.
  void set_ranges() {
    ylo_ = 0.0, yhi_ = 0.0;
    for (const auto& r : wp_.rows) {
      if (!plotted(r)) continue;
      xlo_ = std::min(xlo_, *r.wall_time_s), xhi_ = std::max(xhi_, *r.wall_time_s);
      const double e = percent_of(r.rel_error_w), b = percent_of(bar_of(r));
      ylo_ = std::min(ylo_, e - b), yhi_ = std::max(yhi_, e + b);
    }
    for (const auto& r : wp_.references)
      if (r.wall_time_s && *r.wall_time_s > 0)
        xlo_ = std::min(xlo_, *r.wall_time_s), xhi_ = std::max(xhi_, *r.wall_time_s);
    if (!std::isfinite(xlo_)) xlo_ = 1, xhi_ = 10;
    // At least a decade of wall time and 2 % of error in view, with margins.
    if (xhi_ / xlo_ < 10) {
      const double m = std::sqrt(10 * xlo_ / xhi_);
      xlo_ /= m, xhi_ *= m;
    }
    xlo_ /= 1.6, xhi_ *= 1.6;
    if (yhi_ - ylo_ < 2.0) {
      const double m = (2.0 - (yhi_ - ylo_)) / 2;
      ylo_ -= m, yhi_ += m;
    }
    const double pad = 0.08 * (yhi_ - ylo_);
    ylo_ -= pad, yhi_ += pad;
  }

  double px(double x0, double t) const {
    return x0 + (std::log10(t) - std::log10(xlo_)) / (std::log10(xhi_) - std::log10(xlo_)) * w;
  }
  double py(double pct) const {
    pct = std::clamp(pct, ylo_, yhi_);
    return y0 + h - (pct - ylo_) / (yhi_ - ylo_) * h;
  }

  void draw_panel(plot::Canvas& c, std::size_t a) const {
    using plot::Anchor;
    const double angle = angles_[a], x0 = 90 + a * (w + gap);
    for (double t : report::log_ticks(xlo_, xhi_)) {
      c.line(px(x0, t), y0, px(x0, t), y0 + h, "#ddd");
      c.text(px(x0, t), y0 + h + 18, fmt::format("{:g}", t), Anchor::kMiddle);
    }
    for (double e : report::ticks(ylo_, yhi_)) {
      c.line(x0, py(e), x0 + w, py(e), "#ddd");
      c.text(x0 - 6, py(e) + 4, e == 0.0 ? std::string("0") : fmt::format("{:+g}", e), Anchor::kEnd);
    }
    c.line(x0, py(0.0), x0 + w, py(0.0), "#555", 1.2, {}, "zero");
    c.stroke_rect(x0, y0, w, h, "#000", "panel");
    c.text(x0 + w / 2, y0 - 8, fmt::format("θ = {:g}°", angle), Anchor::kMiddle);
    c.text(x0 + w / 2, y0 + h + 40, "wall time of one run (s)", Anchor::kMiddle);
    if (a == 0)
      c.label(x0 - 62, y0 + h / 2, "⟨⟨w_{p}⟩⟩ / ⟨⟨w_{p}⟩⟩_{ref} − 1 (%)", Anchor::kMiddle, 13, true);
    // The reference: at 0 on the error axis, and its cost.
    for (const auto& r : wp_.references) {
      if (r.angle_deg != angle || !r.wall_time_s || *r.wall_time_s <= 0) continue;
      const double x = px(x0, *r.wall_time_s);
      c.line(x, y0, x, y0 + h, "#555", 1.0, {6, 4}, "reference");
      c.text(x - 4, y0 + h - 6, wp_.reference_group, Anchor::kStart, 11, "#555", true);
    }
    std::vector<Box> taken;
    for (std::size_t g = 0; g < groups_.size(); ++g) draw_group(c, x0, angle, g, taken);
  }

  struct Box {
    double x0, y0, x1, y1;
    bool overlaps(const Box& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
  };

  /// Where a label of width `tw` next to a marker at (x, y) goes: the first of eight places around
  /// it (right above, right below, left above, ...) that overlaps no label, marker or the frame
  /// edge already placed; else further down on the right.
  static Box place_label(double x, double y, double tw, double x0, const std::vector<Box>& taken) {
    constexpr double th = 11;  // the text's height at 10 px
    const double right = x + 7, left = x - 7 - tw;
    const double spots[][2] = {{right, y - 5}, {right, y + 5 + th}, {left, y - 5},       {left, y + 5 + th},
                               {right, y + 4}, {left, y + 4},       {right, y - 5 - th}, {left, y - 5 - th}};
    for (const auto& s : spots) {
      const Box b{s[0], s[1] - th, s[0] + tw, s[1]};
      if (b.x0 < x0 + 2 || b.x1 > x0 + w - 2 || b.y0 < y0 + 2 || b.y1 > y0 + h - 2) continue;
      if (std::none_of(taken.begin(), taken.end(), [&](const Box& o) { return b.overlaps(o); })) return b;
    }
    double base = y + 5 + th;
    Box b{right, base - th, right + tw, base};
    while (std::any_of(taken.begin(), taken.end(), [&](const Box& o) { return b.overlaps(o); }) &&
           b.y1 < y0 + h)
      b.y0 += th, b.y1 += th;
    return b;
  }

  /// One group at one angle, joined in the order of the varied setting, each point labelled with
  /// its setting where no other label or marker is.
  void draw_group(plot::Canvas& c, double x0, double angle, std::size_t g, std::vector<Box>& taken) const {
    const char* color = report::color(g);
    std::vector<const WorkPrecisionRow*> mine;
    for (const auto& r : wp_.rows)
      if (r.group == groups_[g] && r.angle_deg == angle && plotted(r)) mine.push_back(&r);
    if (mine.empty()) return;
    std::stable_sort(mine.begin(), mine.end(), [](const WorkPrecisionRow* p, const WorkPrecisionRow* q) {
      return setting_before(p->setting, q->setting);
    });
    auto at = [&](const WorkPrecisionRow* r) {
      return std::pair{px(x0, *r->wall_time_s), py(percent_of(r->rel_error_w))};
    };
    std::vector<std::pair<double, double>> line;
    for (const auto* r : mine) line.push_back(at(r));
    c.polyline(line, color, 1.5, "group");
    c.clip(x0, y0, w, h);  // bars are clipped to the panel's frame
    for (const auto* r : mine) {
      if (!(bar_of(*r) > 0)) continue;  // none: no bar
      const double e = percent_of(r->rel_error_w), b = percent_of(bar_of(*r)), x = at(r).first;
      c.line(x, py(e - b), x, py(e + b), color, 1.0, {}, "errorbar");
      c.line(x - 4, py(e + b), x + 4, py(e + b), color);
      c.line(x - 4, py(e - b), x + 4, py(e - b), color);
    }
    c.unclip();
    for (const auto* r : mine) {
      const auto [x, y] = at(r);
      c.marker(report::marker_kind(g), x, y, color);
      taken.push_back({x - 5, y - 5, x + 5, y + 5});
    }
    for (const auto* r : mine) {
      const std::string label = setting_label(r->setting);
      if (label.empty()) continue;
      const auto [x, y] = at(r);
      const Box b = place_label(x, y, c.text_width(label, 10), x0, taken);
      taken.push_back(b);
      c.text(b.x0, b.y1 - 1, label, plot::Anchor::kStart, 10, color, false, "setting");
    }
  }

  /// The legend right of the panels, and the caption: what a bar is and how to read one.
  void draw_legend(plot::Canvas& c) const {
    const double lx = 90 + angles_.size() * (w + gap) - gap + 20;
    double ly = y0 + 10;
    for (std::size_t g = 0; g < groups_.size(); ++g, ly += 20) {
      c.marker(report::marker_kind(g), lx + 8, ly, report::color(g));
      c.text(lx + 20, ly + 4, groups_[g], plot::Anchor::kStart, 13, "#000", false, "legend");
    }
    c.line(lx, ly, lx + 16, ly, "#555", 1.2);
    c.text(lx + 20, ly + 4, fmt::format("reference ({})", wp_.reference_group));
    ly += 20;
    c.line(lx, ly, lx + 16, ly, "#555", 1.0, {6, 4});
    c.text(lx + 20, ly + 4, "its wall time");
    const bool any_without = std::any_of(wp_.rows.begin(), wp_.rows.end(), [&](const WorkPrecisionRow& r) {
      return plotted(r) && !(bar_of(r) > 0);
    });
    c.text(90, height() - 30,
           "bars: the interval that holds the true difference ~68 % of the time (the replicas' scatter of "
           "the point "
           "and of the reference, Student's t at Welch's degrees of freedom)",
           plot::Anchor::kStart, 11, "#333", false, "caption");
    c.text(
        90, height() - 14,
        std::string("a bar that crosses 0: the setting cannot be told from the reference at these errors") +
            (any_without ? "; no bar: a run gave no error estimate (window too short)" : ""),
        plot::Anchor::kStart, 11, "#333", false, "caption");
  }

  const WorkPrecision& wp_;
  std::vector<std::string> groups_;
  std::vector<double> angles_;
  double xlo_ = INFINITY, xhi_ = -INFINITY, ylo_ = 0, yhi_ = 0;
};

}  // namespace

plot::Plot work_precision_plot(const WorkPrecision& wp, const std::string& title, plot::Format format) {
  const WorkPrecisionFigure figure(wp);
  return plot::render(figure.width(), WorkPrecisionFigure::height(), format,
                      [&](plot::Canvas& c) { figure.draw(c, title); });
}

}  // namespace boycott::driver
