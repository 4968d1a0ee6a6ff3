// `boycott query ...`: results read from a study database (opened read-only).
#include <cstdio>
#include <fstream>
#include <memory>
#include <stdexcept>

#include <fmt/format.h>

#include "core/error.hpp"
#include "driver/cli/command_line.hpp"
#include "driver/report/curve.hpp"
#include "driver/report/curve_query.hpp"
#include "driver/report/listing_format.hpp"
#include "driver/report/peak.hpp"
#include "driver/report/peak_query.hpp"
#include "driver/report/runs_query.hpp"
#include "driver/report/validation_query.hpp"
#include "driver/report/work_precision.hpp"
#include "driver/run/runner.hpp"
#include "driver/store/store.hpp"

namespace boycott::driver::cli {
namespace {

struct QueryArgs {
  std::string db, study, group, format = "table", plot, reference = "reference";
  bool overlay_paper = false;
};

void add_db(CLI::App* cmd, QueryArgs& a) {
  cmd->add_option("--db", a.db, "results database")->required();
}

/// --db, --study (a filter) and --format: what the listings of every study's cases take.
void add_listing_options(CLI::App* cmd, QueryArgs& a) {
  add_db(cmd, a);
  cmd->add_option("--study", a.study, "only this study");
  add_format(cmd, a.format);
}

void write_plot(const std::string& path, const std::string& data) {
  std::ofstream out(path, std::ios::binary);
  out << data;
  if (!out) throw std::runtime_error(fmt::format("cannot write '{}'", path));
}

int run_query_curve(const QueryArgs& a) {
  const auto format = parse_listing_format(a.format);
  if (a.overlay_paper && a.plot.empty())
    throw InputError("--overlay-paper draws on the plot: give --plot FILE.svg (or .pdf) too");
  auto db = open_for_query(a.db);
  const auto pts = query_curve(db, a.study, a.group);
  if (pts.empty())
    throw InputError(fmt::format("no finished cases of study '{}'{} in '{}'", a.study,
                                 a.group.empty() ? "" : " group '" + a.group + "'", a.db));
  // A plot name with an extension of no format is refused before anything is printed.
  const auto plot_format = a.plot.empty() ? plot::Format::kSvg : plot::format_of_path(a.plot);
  std::fputs(format_curve(pts, format).c_str(), stdout);
  if (!a.plot.empty()) {
    const auto paper = parse_paper_values(paper_reference_csv());
    const auto peaks = query_peak(db, a.study, a.group);
    write_plot(a.plot, curve_plot(pts, fmt::format("study {}", a.study), a.overlay_paper ? &paper : nullptr,
                                  plot_format, &peaks)
                           .data);
  }
  return 0;
}

int run_query_peak(const QueryArgs& a) {
  const auto format = parse_listing_format(a.format);
  auto db = open_for_query(a.db);
  require_study(db, a.study);
  const auto rows = query_peak(db, a.study, a.group);
  if (rows.empty())
    throw InputError(fmt::format("no curve of study '{}'{} in '{}' has a finished point with an error",
                                 a.study, a.group.empty() ? "" : " group '" + a.group + "'", a.db));
  std::fputs(format_peak(rows, format).c_str(), stdout);
  return 0;
}

Command setup_query_peak(CLI::App* parent) {
  auto a = std::make_shared<QueryArgs>();
  auto* cmd = parent->add_subcommand("peak",
                                     "per curve, the angle and <<w_p>> of its peak with their 68 % "
                                     "intervals, r_acc there, the points it rests "
                                     "on and whether it is resolved");
  add_db(cmd, *a);
  cmd->add_option("--study", a->study, "study name")->required();
  cmd->add_option("--group", a->group, "only this group");
  add_format(cmd, a->format);
  return {cmd, [a] { return run_query_peak(*a); }};
}

Command setup_query_curve(CLI::App* parent) {
  auto a = std::make_shared<QueryArgs>();
  auto* cmd = parent->add_subcommand("curve", "<<w_p>> and r_acc per group and angle");
  add_db(cmd, *a);
  cmd->add_option("--study", a->study, "study name")->required();
  cmd->add_option("--group", a->group, "only this group");
  add_format(cmd, a->format);
  cmd->add_option(
      "--plot", a->plot,
      "also draw the curves (like Fig. 14 of the paper): PDF for FILE.pdf, PNG for FILE.png, SVG otherwise");
  cmd->add_flag("--overlay-paper", a->overlay_paper,
                "with --plot: also the values the paper states (studies/reference/zeng2021.csv)");
  return {cmd, [a] { return run_query_curve(*a); }};
}

Command setup_query_validation(CLI::App* parent) {
  auto a = std::make_shared<QueryArgs>();
  auto* cmd = parent->add_subcommand(
      "validation",
      "per finished case: the scene's measured errors against its reference, and the wall time");
  add_listing_options(cmd, *a);
  return {cmd, [a] {
            const auto format = parse_listing_format(a->format);
            auto db = open_for_query(a->db);
            std::fputs(format_validation(query_validation(db, a->study), format).c_str(), stdout);
            return 0;
          }};
}

int run_query_work_precision(const QueryArgs& a) {
  const auto format = parse_listing_format(a.format);
  auto db = open_for_query(a.db);
  const auto wp = query_work_precision(db, a.study, a.reference);
  if (wp.rows.empty())
    throw InputError(fmt::format("no finished cases of study '{}' outside the reference group '{}' in '{}'",
                                 a.study, a.reference, a.db));
  std::fputs(format_work_precision(wp, format).c_str(), stdout);
  if (!a.plot.empty())
    write_plot(
        a.plot,
        work_precision_plot(
            wp, fmt::format("study {}: error against run time (reference group '{}')", a.study, a.reference),
            plot::format_of_path(a.plot))
            .data);
  return 0;
}

Command setup_query_work_precision(CLI::App* parent) {
  auto a = std::make_shared<QueryArgs>();
  auto* cmd = parent->add_subcommand(
      "work-precision", "error of <<w_p>> and r_acc against the reference group, and the run time it cost");
  add_db(cmd, *a);
  cmd->add_option("--study", a->study, "study name")->required();
  cmd->add_option("--reference", a->reference, "group holding the reference runs, one per angle")
      ->capture_default_str();
  add_format(cmd, a->format);
  cmd->add_option(
      "--plot", a->plot,
      "also draw |error| against wall time (log-log): PDF for FILE.pdf, PNG for FILE.png, SVG otherwise");
  return {cmd, [a] { return run_query_work_precision(*a); }};
}

Command setup_query_runs(CLI::App* parent) {
  auto a = std::make_shared<QueryArgs>();
  auto* cmd = parent->add_subcommand(
      "runs", "per finished run: its window, error basis, correlation times, wall time and core-hours");
  add_db(cmd, *a);
  cmd->add_option("--study", a->study, "study name")->required();
  add_format(cmd, a->format);
  return {cmd, [a] {
            const auto format = parse_listing_format(a->format);
            auto db = open_for_query(a->db);
            std::fputs(format_runs(query_runs(db, a->study), format).c_str(), stdout);
            return 0;
          }};
}

Command setup_query_cases(CLI::App* parent) {
  auto a = std::make_shared<QueryArgs>();
  auto* cmd = parent->add_subcommand("cases", "list cases and their status");
  add_listing_options(cmd, *a);
  return {cmd, [a] {
            const auto format = parse_listing_format(a->format);
            auto db = open_for_query(a->db);
            std::fputs(format_cases(case_states_now(db, a->db, a->study, 2), format).c_str(), stdout);
            return 0;
          }};
}

}  // namespace

std::vector<Command> setup_query_commands(CLI::App& app) {
  auto* group = app.add_subcommand("query", "read results from a study database");
  group->require_subcommand(1);
  return {setup_query_curve(group),          setup_query_peak(group), setup_query_validation(group),
          setup_query_work_precision(group), setup_query_runs(group), setup_query_cases(group)};
}

}  // namespace boycott::driver::cli
