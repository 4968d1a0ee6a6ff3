#include "driver/report/runs_query.hpp"

#include <fmt/format.h>

#include "driver/report/report_util.hpp"

namespace boycott::driver {

namespace {

std::string window_text(const RunRecord& r) {
  if (!r.average_from_s || !r.end_s) return "-";
  return fmt::format("{:.4g}-{:.4g}", *r.average_from_s, *r.end_s);  // 10.0001: a last step past 10 s
}

std::string point_text(const RunRecord& r) {
  if (!r.w_m_s) return "-";
  if (!r.error_m_s) return fmt::format("{:.2f}", *r.w_m_s * 1e3);
  return fmt::format("{:.2f} ± {:.2f}", *r.w_m_s * 1e3, *r.error_m_s * 1e3);
}

std::string basis_text(const RunRecord& r) {
  if (!r.error_method) return "-";
  return r.error_dof ? fmt::format("{} ({:.3g} dof)", *r.error_method, *r.error_dof) : *r.error_method;
}

}  // namespace

std::vector<RunRecord> query_runs(Database& db, const std::string& study) {
  require_study(db, study);
  return run_records(db, study);
}

std::optional<double> core_hours(const RunRecord& r) {
  if (!r.wall_time_s || !r.ranks) return std::nullopt;
  return *r.wall_time_s * static_cast<double>(*r.ranks) / 3600.0;
}

std::optional<double> cpu_core_hours(const RunRecord& r) {
  if (!r.cpu_time_s) return std::nullopt;
  return *r.cpu_time_s / 3600.0;
}

std::string format_runs(const std::vector<RunRecord>& rows, ListingFormat f) {
  if (f != ListingFormat::kTable) {
    report::TextTable t(
        {"case_id", "group", "angle_deg", "n_particles", "end_s", "average_from_s",
         "mean_settling_velocity_m_s", "error_m_s", "error_method", "error_dof", "correlation_time_s",
         "window_correlation_times", "wall_time_s", "mpi_ranks", "core_hours", "cpu_core_hours"},
        {false, false, true, true, true, true, true, true, false, true, true, true, true, true, true, true});
    for (const auto& r : rows)
      t.add({r.case_id, r.group, fmt::format("{:g}", r.angle_deg), report::csv_count(r.n_particles),
             report::csv_number(r.end_s), report::csv_number(r.average_from_s), report::csv_number(r.w_m_s),
             report::csv_number(r.error_m_s), r.error_method.value_or(""), report::csv_number(r.error_dof),
             report::csv_number(r.correlation_time_s), report::csv_number(r.window_correlation_times),
             report::csv_number(r.wall_time_s), report::csv_count(r.ranks), report::csv_number(core_hours(r)),
             report::csv_number(cpu_core_hours(r))});
    return f == ListingFormat::kCsv ? t.csv() : t.json().dump(2) + "\n";
  }
  if (rows.empty()) return "(no finished runs)\n";
  report::TextTable t({"group", "case", "angle", "particles", "window (s)", "<<w_p>> (mm/s)", "error basis",
                       "tau_int (s)", "corr. times", "wall (h)", "ranks", "core-h", "CPU core-h"},
                      {false, false, true, true, true, true, false, true, true, true, true, true, true});
  double total = 0.0, cpu_total = 0.0;
  int priced = 0, cpu_priced = 0;
  for (const auto& r : rows) {
    const auto ch = core_hours(r), cpu = cpu_core_hours(r);
    if (ch) total += *ch, ++priced;
    if (cpu) cpu_total += *cpu, ++cpu_priced;
    t.add({r.group, r.case_id, fmt::format("{:g}", r.angle_deg), report::csv_count(r.n_particles),
           window_text(r), point_text(r), basis_text(r),
           r.correlation_time_s ? fmt::format("{:.3g}", *r.correlation_time_s) : "-",
           r.window_correlation_times ? fmt::format("{:.1f}", *r.window_correlation_times) : "-",
           r.wall_time_s ? fmt::format("{:.2f}", *r.wall_time_s / 3600.0) : "-", report::csv_count(r.ranks),
           ch ? fmt::format("{:.2f}", *ch) : "-", cpu ? fmt::format("{:.2f}", *cpu) : "-"});
  }
  std::string s = t.str();
  s += fmt::format(
      "{} runs, {:.1f} core-hours (wall time over each run's attempts x the ranks of the one that "
      "finished it){}\n",
      rows.size(), total,
      priced < static_cast<int>(rows.size())
          ? fmt::format("; {} without a wall time or rank count", rows.size() - priced)
          : "");
  if (cpu_priced > 0)
    s += fmt::format("{:.1f} CPU core-hours in the {} runs that record them (over all their attempts)\n",
                     cpu_total, cpu_priced);
  return s;
}

}  // namespace boycott::driver
