// `boycott stats mean`: the statistics room's rules (solver/stats) on any series a user has, read
// from a CSV file (driver/report/series_table.hpp, series_mean.hpp).
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

#include <fmt/format.h>

#include "core/error.hpp"
#include "driver/cli/command_line.hpp"
#include "driver/report/listing_format.hpp"
#include "driver/report/series_mean.hpp"
#include "driver/report/series_table.hpp"

namespace boycott::driver::cli {
namespace {

struct MeanArgs {
  std::string path, average_from, format = "table";
  std::vector<std::string> columns;
};

int run_stats_mean(const MeanArgs& a) {
  const auto format = parse_listing_format(a.format);
  const auto from = report::parse_average_from(a.average_from);
  std::ifstream in(a.path, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot read '{}'", a.path));
  std::ostringstream text;
  text << in.rdbuf();
  const auto table = report::parse_series_table(text.str(), a.path);
  const auto rows = report::series_means(table, a.columns, from);
  std::fputs(report::format_series_means(rows, format, table.time_s.has_value()).c_str(), stdout);
  return 0;
}

Command setup_stats_mean(CLI::App* parent) {
  auto a = std::make_shared<MeanArgs>();
  auto* cmd = parent->add_subcommand("mean",
                                     "the mean of each column of a CSV series and its covering (~68 %) "
                                     "error, by the rules a run's summary.json "
                                     "uses: batch means (the two halves at least) with Student's t, the "
                                     "correlation time, the start-up transient");
  cmd->add_option("series", a->path,
                  "CSV file: a header of names, rows of numbers; a first column named t or "
                  "time_s is the time (s)")
      ->required();
  cmd->add_option("--column", a->columns,
                  "only this column (repeat for more); default: every numeric column");
  cmd->add_option("--average-from", a->average_from,
                  "average from this time (s; a row index without a time column), or 'auto': from where each "
                  "column's start-up transient is detected to end; default: every row");
  add_format(cmd, a->format);
  return {cmd, [a] { return run_stats_mean(*a); }};
}

}  // namespace

std::vector<Command> setup_stats_commands(CLI::App& app) {
  auto* stats = app.add_subcommand("stats", "statistics of series a user has, by the product's rules");
  stats->require_subcommand(1);
  return {setup_stats_mean(stats)};
}

}  // namespace boycott::driver::cli
