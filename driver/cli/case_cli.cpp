// `boycott case ...`: one case, in this process (case_commands.hpp).
#include <memory>

#include "driver/cli/case_commands.hpp"
#include "driver/cli/command_line.hpp"

namespace boycott::driver::cli {
namespace {

Command setup_case_run(CLI::App* parent, int argc, char** argv, std::vector<std::string>** petsc_options) {
  auto opt = std::make_shared<CaseRunOptions>();
  auto* cmd = parent->add_subcommand("run", "run (or resume) one case; PETSc options may follow '--'");
  cmd->add_option("case", opt->case_file, "case file (TOML)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", opt->out_dir, "run folder (params, checkpoints, outputs)")->required();
  cmd->add_option("--set", opt->overrides, "override a key: section.key=value")->take_all();
  cmd->add_flag("--quiet", opt->quiet, "no progress output");
  cmd->add_option("--progress-every", opt->progress_every_s,
                  "seconds between progress lines when stderr is not a terminal")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--stop-after", opt->stop_after_s,
                  "seconds after which the run checkpoints and stops (exit 75: run again to resume)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--from", opt->from_dir,
                  "branch: start from this run folder's newest kept checkpoint (with this case's parameters)")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--at", opt->at_s, "with --from: the newest checkpoint at or before this time, s")
      ->check(CLI::NonNegativeNumber);
  *petsc_options = &opt->petsc_options;
  return {cmd, [opt, argc, argv] { return case_run(*opt, argc, argv); }};
}

Command setup_case_check(CLI::App* parent) {
  struct Args {
    std::string file;
    std::vector<std::string> sets;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = parent->add_subcommand("check", "validate a case and print its pre-flight report");
  cmd->add_option("case", a->file, "case file (TOML)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--set", a->sets, "override a key: section.key=value")->take_all();
  return {cmd, [a] { return case_check(a->file, a->sets); }};
}

Command setup_case_keys(CLI::App* parent) {
  struct Args {
    std::string scene, format = "table";
  };
  auto a = std::make_shared<Args>();
  auto* cmd = parent->add_subcommand("keys", "list every case key and its default (or a scene's)");
  cmd->add_option("--scene", a->scene, "only the keys this scene reads, at its defaults");
  add_format(cmd, a->format);
  return {cmd, [a] { return case_keys(a->scene, a->format); }};
}

Command setup_case_summarize(CLI::App* parent) {
  struct Args {
    std::vector<std::string> dirs;
    std::string db;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = parent->add_subcommand(
      "summarize",
      "recompute finished inclined_settling runs' statistics of <<w_p>> from their checkpoints "
      "with this build's rules; update summary.json and the database row");
  cmd->add_option("run_dir", a->dirs, "run folders (e.g. FILE.runs/<case_id>)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--db", a->db, "results database whose rows of these runs to update");
  return {cmd, [a] { return case_summarize(a->dirs, a->db); }};
}

}  // namespace

std::vector<Command> setup_case_commands(CLI::App& app, int argc, char** argv,
                                         std::vector<std::string>** petsc_options) {
  auto* group = app.add_subcommand("case", "run or check a single case");
  group->require_subcommand(1);
  return {setup_case_run(group, argc, argv, petsc_options), setup_case_check(group), setup_case_keys(group),
          setup_case_summarize(group)};
}

}  // namespace boycott::driver::cli
