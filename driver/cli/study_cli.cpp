// `boycott study ...`: a study (a matrix of cases) run into its database, here or on Slurm.
#include <unistd.h>

#include <memory>

#include "driver/cli/command_line.hpp"
#include "driver/report/listing_format.hpp"
#include "driver/run/collect.hpp"
#include "driver/run/plan.hpp"
#include "driver/run/runner.hpp"
#include "driver/run/slurm.hpp"

namespace boycott::driver::cli {
namespace {

/// The study file every study subcommand takes first.
void add_study_file(CLI::App* cmd, std::string& file) {
  cmd->add_option("study", file, "study file (TOML)")->required()->check(CLI::ExistingFile);
}

struct StudyRunArgs {
  StudyRunOptions opt;
  bool quiet = false;
};

int run_study_run(StudyRunArgs& a) {
  a.opt.progress_live = !a.quiet && isatty(STDERR_FILENO);
  if (a.quiet) a.opt.progress_every_s = 0;
  require_db_path(a.opt.db_path);
  return study_run(a.opt);
}

Command setup_study_run(CLI::App* parent) {
  auto a = std::make_shared<StudyRunArgs>();
  auto* cmd =
      parent->add_subcommand("run", "run what is missing, resume interrupted cases, retry failed ones");
  add_study_file(cmd, a->opt.study_file);
  cmd->add_option("--db", a->opt.db_path, "results database (SQLite)")->required();
  cmd->add_option("--jobs", a->opt.jobs, "cases run at once")->capture_default_str()->check(kCountRange);
  add_retries(cmd, a->opt.retries, "failed attempts retried per case");
  cmd->add_option("--ranks", a->opt.ranks, "MPI ranks per case (mpirun -n K)")
      ->capture_default_str()
      ->check(kCountRange);
  cmd->add_option("--progress-every", a->opt.progress_every_s,
                  "seconds between progress lines when stderr is not a terminal")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option(
         "--stop-after", a->opt.stop_after_s,
         "seconds after which every running case checkpoints and stops (exit 75: run again to resume)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--quiet", a->quiet, "no progress output");
  // For tests and for other solver builds: the command that runs one case.
  cmd->add_option("--solver-command", a->opt.solver_command, "")->group("");
  return {cmd, [a] { return run_study_run(*a); }};
}

Command setup_study_status(CLI::App* parent) {
  struct Args {
    std::string file, db, format = "table";
    int retries = 2;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = parent->add_subcommand("status", "report the cases of a study and their status");
  add_study_file(cmd, a->file);
  cmd->add_option("--db", a->db, "results database (SQLite)")->required();
  add_retries(cmd, a->retries, "as given to study run");
  add_format(cmd, a->format);
  return {cmd, [a] {
            require_db_path(a->db);
            return study_status(a->file, a->db, a->retries, parse_listing_format(a->format));
          }};
}

Command setup_study_plan(CLI::App* parent) {
  auto opt = std::make_shared<PlanOptions>();
  auto* cmd = parent->add_subcommand(
      "plan", "list the cases with their state and estimated cost, and the study's wall time; runs nothing");
  add_study_file(cmd, opt->study_file);
  cmd->add_option("--db", opt->db_path, "results database (read if it exists: states and the cost model)");
  cmd->add_option("--jobs", opt->jobs, "cases run at once")->capture_default_str()->check(kCountRange);
  cmd->add_option("--ranks", opt->ranks, "MPI ranks per case")->capture_default_str()->check(kCountRange);
  add_format(cmd, opt->format);
  cmd->add_flag("--all", opt->all, "list every case in the table even past 10 000 (else one line per group)");
  cmd->add_flag("--check-model", opt->check_model,
                "also predict each finished case from the other finished runs only (leave one out)");
  return {cmd, [opt] { return study_plan(*opt); }};
}

Command setup_study_submit(CLI::App* parent) {
  auto opt = std::make_shared<SlurmSubmitOptions>();
  auto* cmd = parent->add_subcommand(
      "submit",
      "submit the pending cases as a Slurm job array (one case per task); the tasks write only run folders");
  add_study_file(cmd, opt->study_file);
  cmd->add_option("--db", opt->db_path, "results database (SQLite)")->required();
  cmd->add_option("--scheduler", opt->scheduler, "the batch system: slurm (the only one)")->required();
  cmd->add_option("--ranks", opt->ranks, "MPI ranks per case")->capture_default_str()->check(kCountRange);
  cmd->add_option("--launcher", opt->launcher, "how a case starts its ranks: srun (--mpi=pmix) or mpirun")
      ->capture_default_str();
  cmd->add_option("--time", opt->time, "wall-time limit of each task (HH:MM:SS)");
  cmd->add_option("--partition", opt->partition, "Slurm partition");
  cmd->add_option("--max-running", opt->max_running, "array tasks at once (%K; 0: no limit)")
      ->capture_default_str();
  add_retries(cmd, opt->retries, "failed attempts retried per case");
  cmd->add_option("--sbatch-arg", opt->sbatch_args,
                  "an extra sbatch option (repeatable), e.g. --sbatch-arg=--account=X")
      ->allow_extra_args(false);
  cmd->add_flag("--dry-run", opt->dry_run, "print the batch script; write and submit nothing");
  cmd->add_option("--solver-command", opt->solver_command, "")->group("");
  return {cmd, [opt] {
            require_db_path(opt->db_path);
            return study_submit(*opt);
          }};
}

Command setup_study_collect(CLI::App* parent) {
  struct Args {
    std::string file, db;
    int retries = 2;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = parent->add_subcommand(
      "collect", "record the run folders that tasks finished (study submit) in the database; safe to repeat");
  add_study_file(cmd, a->file);
  cmd->add_option("--db", a->db, "results database (SQLite)")->required();
  add_retries(cmd, a->retries, "as given to study run");
  return {cmd, [a] {
            require_db_path(a->db);
            return study_collect(a->file, a->db, a->retries);
          }};
}

}  // namespace

std::vector<Command> setup_study_commands(CLI::App& app) {
  auto* group = app.add_subcommand("study", "run a study (a matrix of cases) into a database");
  group->require_subcommand(1);
  return {setup_study_run(group), setup_study_status(group), setup_study_plan(group),
          setup_study_submit(group), setup_study_collect(group)};
}

}  // namespace boycott::driver::cli
