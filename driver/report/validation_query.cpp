#include "driver/report/validation_query.hpp"

#include <cmath>
#include <set>

#include <fmt/format.h>

#include "core/scene_specs.hpp"
#include "driver/report/report_util.hpp"

namespace boycott::driver {

namespace {

/// A stored error for people. The scenes' "error" keys are relative errors ("rel" in the name);
/// anything else (a count, an absolute error with a unit) is shown as it is.
std::string table_text(const nlohmann::json& v, bool relative) {
  if (v.is_null()) return "-";
  if (v.is_number())
    return relative ? report::percent(v.get<double>()) : fmt::format("{:.4g}", v.get<double>());
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_string()) return v.get<std::string>();
  std::string s;
  if (v.is_array()) {
    for (const auto& e : v) s += (s.empty() ? "" : ", ") + table_text(e, relative);
    return "[" + s + "]";
  }
  for (const auto& [k, e] : v.items())
    s += fmt::format("{}{}: {}", s.empty() ? "" : ", ", k, table_text(e, relative));
  return "{" + s + "}";
}

std::string csv_text(const nlohmann::json& v) {
  if (v.is_null()) return "";
  if (v.is_number()) return fmt::format("{:.9g}", v.get<double>());
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

/// The tolerance the scene holds this error to, or null.
const SceneSpec::Tolerance* tolerance_of(const std::string& scene, const std::string& key) {
  for (const auto& spec : scene_specs())
    if (spec.name == scene)
      for (const auto& t : spec.tolerances)
        if (t.error_key == key) return &t;
  return nullptr;
}

bool passes(const SceneSpec::Tolerance& tol, const nlohmann::json& v) {
  return v.is_number() && std::abs(v.get<double>()) <= tol.max_abs;
}

}  // namespace

std::vector<ValidationRow> query_validation(Database& db, const std::string& study) {
  if (!study.empty()) require_study(db, study);
  std::vector<ValidationRow> rows;
  for (auto& stored : stored_results(db, study)) {
    ValidationRow r;
    r.study = stored.study.value_or("-");
    r.group = stored.group.value_or("-");
    r.case_id = std::move(stored.case_id);
    r.scene = std::move(stored.scene);
    r.w_m_s = stored.w_m_s;
    r.wall_time_s = stored.wall_time_s;
    // Written by record_result as an object; anything else (hand-edited, older drivers) is shown
    // as one entry rather than refused, so one odd row does not hide the others.
    if (const auto& text = stored.validation_errors_json) {
      const auto j = nlohmann::json::parse(*text, nullptr, /*allow_exceptions=*/false);
      if (j.is_object())
        for (const auto& [k, v] : j.items()) r.errors.emplace_back(k, v);
      else if (!j.is_null())
        r.errors.emplace_back("validation_errors_json", j.is_discarded() ? nlohmann::json(*text) : j);
    }
    rows.push_back(std::move(r));
  }
  for (auto& r : rows) r.values = case_swept_values(db, r.case_id);
  return rows;
}

std::string format_validation(const std::vector<ValidationRow>& rows, ListingFormat f) {
  if (f == ListingFormat::kJson) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& r : rows) {
      nlohmann::json values = nlohmann::json::object(), errors = nlohmann::json::object();
      for (const auto& v : r.values) values[v.key] = report::value_json(v);
      nlohmann::json checks = nlohmann::json::array();
      for (const auto& [k, v] : r.errors) {
        errors[k] = v;
        if (const auto* tol = tolerance_of(r.scene, k))
          checks.push_back({{"error", k},
                            {"value", v},
                            {"tolerance", tol->max_abs},
                            {"against", tol->against},
                            {"pass", passes(*tol, v)}});
      }
      j.push_back({{"study", r.study},
                   {"group", r.group},
                   {"case_id", r.case_id},
                   {"scene", r.scene},
                   {"values", values},
                   {"errors", errors},
                   {"checks", checks},
                   {"mean_settling_velocity_m_s", report::json_number(r.w_m_s)},
                   {"wall_time_s", report::json_number(r.wall_time_s)}});
    }
    return j.dump(2) + "\n";
  }
  if (f == ListingFormat::kCsv) {
    // Scenes report different keys: one column per key seen in any row, empty where absent.
    std::set<std::string> keys;
    for (const auto& r : rows)
      for (const auto& e : r.errors) keys.insert(e.first);
    std::string s = "study,group,case_id,scene,values,mean_settling_velocity_m_s,wall_time_s";
    // Appended in two steps: GCC 12 warns (-Wrestrict, a false positive) on "," + std::string.
    for (const auto& k : keys) s.append(",").append(report::csv_field(k));
    s += "\n";
    for (const auto& r : rows) {
      s += fmt::format("{},{},{},{},{},{},{}", report::csv_field(r.study), report::csv_field(r.group),
                       r.case_id, report::csv_field(r.scene),
                       report::csv_field(r.values.empty() ? "" : report::join_values(r.values)),
                       report::csv_number(r.w_m_s), report::csv_number(r.wall_time_s));
      for (const auto& k : keys) {
        std::string cell;
        for (const auto& [ek, v] : r.errors)
          if (ek == k) cell = csv_text(v);
        s.append(",").append(report::csv_field(cell));
      }
      s += "\n";
    }
    return s;
  }
  if (rows.empty()) return "(no finished cases)\n";
  report::TextTable t({"study", "group", "case", "scene", "<<w_p>> (mm/s)", "wall (s)", "values", "errors"},
                      {false, false, false, false, true, true, false, false});
  for (const auto& r : rows) {
    std::string errs;
    for (const auto& [k, v] : r.errors) {
      errs += fmt::format("{}{}={}", errs.empty() ? "" : "  ", k,
                          table_text(v, k.find("rel") != std::string::npos));
      if (const auto* tol = tolerance_of(r.scene, k))
        errs += fmt::format(" (|.| <= {:g} %: {})", 100.0 * tol->max_abs, passes(*tol, v) ? "pass" : "FAIL");
    }
    t.add({r.study, r.group, r.case_id, r.scene, r.w_m_s ? fmt::format("{:.4f}", *r.w_m_s * 1e3) : "-",
           r.wall_time_s ? report::seconds(*r.wall_time_s) : "-", report::join_values(r.values),
           errs.empty() ? "-" : errs});
  }
  return t.str();
}

}  // namespace boycott::driver
