// boycott: the command-line front end. Subcommands follow design brief section 7.
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string_view>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "core/error.hpp"
#include "core/version.hpp"
#include "driver/case_commands.hpp"
#include "driver/collect.hpp"
#include "driver/curve.hpp"
#include "driver/database.hpp"
#include "driver/plan.hpp"
#include "driver/runner.hpp"
#include "driver/slurm.hpp"
#include "driver/store.hpp"
#include "driver/terminal_text.hpp"
#include "driver/validation_query.hpp"
#include "driver/work_precision.hpp"

namespace {

// Counts a user gives (jobs, ranks, retries): whole numbers in a range CLI11 names in its message.
const CLI::Range kCountRange(1, 100000);
const CLI::Range kRetriesRange(0, 1000);
// Every listing command's --format: the same choices, listed in help, refused alike.
const CLI::IsMember kFormatChoices({"table", "csv", "json"});

CLI::Option* add_format(CLI::App* cmd, std::string& format) {
  return cmd->add_option("--format", format, "table, csv or json")
      ->capture_default_str()
      ->check(kFormatChoices);
}

int run_guarded(const std::function<int()>& fn) {
  try {
    return fn();
  } catch (const boycott::driver::DatabaseError& e) {
    // An unusable database (unwritable path, newer schema) is bad input to the driver.
    std::fprintf(stderr, "error: %s\n", boycott::driver::printable(e.what()).c_str());
    return boycott::kExitInputError;
  } catch (const std::exception& e) {
    // A failed write (disk full, I/O error) keeps the last good checkpoint: StorageError, 74.
    std::fprintf(stderr, "error: %s\n", boycott::driver::printable(e.what()).c_str());
    return boycott::exit_code_of(e);
  }
}

/// --db names a file: an empty one would be SQLite's private temporary database.
void require_db_path(const std::string& path) {
  if (path.empty()) throw boycott::InputError("--db is empty: name the study database file");
}

/// A query's database: read-only (a read-only file or mount can be queried; nothing migrated).
boycott::driver::Database open_for_query(const std::string& path) {
  require_db_path(path);
  return boycott::driver::Database(path, boycott::driver::OpenMode::kReadOnly);
}

/// A command line the program did not understand: CLI11's message, naming the word, and exit 2
/// (--help and --version exit 0).
int usage_error(CLI::App& app, const CLI::ParseError& e, int argc, char** argv) {
  if (e.get_exit_code() == 0) return app.exit(e);
  // "A subcommand is required" after a word that is no command: name the word and the choices.
  const CLI::App* level = &app;
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.empty() || word[0] == '-') break;
    const CLI::App* next = nullptr;
    for (const auto* sub : level->get_subcommands({}))
      if (sub->get_name() == word) next = sub;
    if (next == nullptr) {
      if (level->get_subcommands({}).empty()) break;
      std::string names;
      for (const auto* sub : level->get_subcommands({}))
        names += (names.empty() ? "" : ", ") + sub->get_name();
      std::fprintf(
          stderr,
          "error: unknown command '%s' (expected one of: %s)\nRun with --help for more information.\n",
          boycott::driver::printable(word).c_str(), names.c_str());
      return boycott::kExitInputError;
    }
    level = next;
  }
  std::fprintf(stderr, "error: %s\nRun with --help for more information.\n",
               boycott::driver::printable(e.what()).c_str());
  return boycott::kExitInputError;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "boycott: unresolved CFD-DEM of proppant settling in inclined narrow channels, and its study driver"};
  app.require_subcommand(1);
  app.footer(
      "Exit codes: 0 done; 2 bad input or usage; 3 unphysical state; 4 unusable checkpoint or run folder; 74 "
      "storage error (nothing lost); 75 interrupted after a checkpoint (run again to resume); 1 other "
      "failure.");
  app.set_version_flag("--version", fmt::format("boycott {}+{}", boycott::kVersion, boycott::kGitRevision));

  auto* case_cmd = app.add_subcommand("case", "run or check a single case");
  case_cmd->require_subcommand(1);

  boycott::driver::CaseRunOptions run_opt;
  auto* run = case_cmd->add_subcommand("run", "run (or resume) one case; PETSc options may follow '--'");
  run->add_option("case", run_opt.case_file, "case file (TOML)")->required()->check(CLI::ExistingFile);
  run->add_option("--out", run_opt.out_dir, "run folder (params, checkpoints, outputs)")->required();
  run->add_option("--set", run_opt.overrides, "override a key: section.key=value")->take_all();
  run->add_flag("--quiet", run_opt.quiet, "no progress output");
  run->add_option("--progress-every", run_opt.progress_every_s,
                  "seconds between progress lines when stderr is not a terminal")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  run->add_option("--from", run_opt.from_dir,
                  "branch: start from this run folder's newest kept checkpoint (with this case's parameters)")
      ->check(CLI::ExistingDirectory);
  run->add_option("--at", run_opt.at_s, "with --from: the newest checkpoint at or before this time, s")
      ->check(CLI::NonNegativeNumber);

  std::string check_file;
  std::vector<std::string> check_sets;
  auto* check = case_cmd->add_subcommand("check", "validate a case and print its pre-flight report");
  check->add_option("case", check_file, "case file (TOML)")->required()->check(CLI::ExistingFile);
  check->add_option("--set", check_sets, "override a key: section.key=value")->take_all();

  std::string keys_scene;
  auto* keys = case_cmd->add_subcommand("keys", "list every case key and its default (or a scene's)");
  keys->add_option("--scene", keys_scene, "only the keys this scene reads, at its defaults");
  std::string keys_format = "table";
  add_format(keys, keys_format);

  std::vector<std::string> summarize_dirs;
  std::string summarize_db;
  auto* summarize = case_cmd->add_subcommand(
      "summarize",
      "recompute finished inclined_settling runs' statistics of <<w_p>> from their checkpoints "
      "with this build's rules; update summary.json and the database row");
  summarize->add_option("run_dir", summarize_dirs, "run folders (e.g. FILE.runs/<case_id>)")
      ->required()
      ->check(CLI::ExistingDirectory);
  summarize->add_option("--db", summarize_db, "results database whose rows of these runs to update");

  // ---- study ----
  auto* study_cmd = app.add_subcommand("study", "run a study (a matrix of cases) into a database");
  study_cmd->require_subcommand(1);
  boycott::driver::StudyRunOptions sopt;
  auto* srun =
      study_cmd->add_subcommand("run", "run what is missing, resume interrupted cases, retry failed ones");
  srun->add_option("study", sopt.study_file, "study file (TOML)")->required()->check(CLI::ExistingFile);
  srun->add_option("--db", sopt.db_path, "results database (SQLite)")->required();
  srun->add_option("--jobs", sopt.jobs, "cases run at once")->capture_default_str()->check(kCountRange);
  srun->add_option("--retries", sopt.retries, "failed attempts retried per case")
      ->capture_default_str()
      ->check(kRetriesRange);
  srun->add_option("--ranks", sopt.ranks, "MPI ranks per case (mpirun -n K)")
      ->capture_default_str()
      ->check(kCountRange);
  // For tests and for other solver builds: the command that runs one case.
  bool study_quiet = false;
  srun->add_option("--progress-every", sopt.progress_every_s,
                   "seconds between progress lines when stderr is not a terminal")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  srun->add_flag("--quiet", study_quiet, "no progress output");
  srun->add_option("--solver-command", sopt.solver_command, "")->group("");
  std::string status_file, status_db, status_format = "table";
  int status_retries = 2;
  auto* sstatus = study_cmd->add_subcommand("status", "report the cases of a study and their status");
  sstatus->add_option("study", status_file, "study file (TOML)")->required()->check(CLI::ExistingFile);
  sstatus->add_option("--db", status_db, "results database (SQLite)")->required();
  sstatus->add_option("--retries", status_retries, "as given to study run")
      ->capture_default_str()
      ->check(kRetriesRange);
  add_format(sstatus, status_format);
  boycott::driver::PlanOptions plan_opt;
  auto* splan = study_cmd->add_subcommand(
      "plan", "list the cases with their state and estimated cost, and the study's wall time; runs nothing");
  splan->add_option("study", plan_opt.study_file, "study file (TOML)")->required()->check(CLI::ExistingFile);
  splan->add_option("--db", plan_opt.db_path,
                    "results database (read if it exists: states and the cost model)");
  splan->add_option("--jobs", plan_opt.jobs, "cases run at once")->capture_default_str()->check(kCountRange);
  splan->add_option("--ranks", plan_opt.ranks, "MPI ranks per case")
      ->capture_default_str()
      ->check(kCountRange);
  add_format(splan, plan_opt.format);
  splan->add_flag("--all", plan_opt.all,
                  "list every case in the table even past 10 000 (else one line per group)");
  splan->add_flag("--check-model", plan_opt.check_model,
                  "also predict each finished case from the other finished runs only (leave one out)");
  boycott::driver::SlurmSubmitOptions subopt;
  auto* ssubmit = study_cmd->add_subcommand(
      "submit",
      "submit the pending cases as a Slurm job array (one case per task); the tasks write only run folders");
  ssubmit->add_option("study", subopt.study_file, "study file (TOML)")->required()->check(CLI::ExistingFile);
  ssubmit->add_option("--db", subopt.db_path, "results database (SQLite)")->required();
  ssubmit->add_option("--scheduler", subopt.scheduler, "the batch system: slurm (the only one)")->required();
  ssubmit->add_option("--ranks", subopt.ranks, "MPI ranks per case")
      ->capture_default_str()
      ->check(kCountRange);
  ssubmit
      ->add_option("--launcher", subopt.launcher, "how a case starts its ranks: srun (--mpi=pmix) or mpirun")
      ->capture_default_str();
  ssubmit->add_option("--time", subopt.time, "wall-time limit of each task (HH:MM:SS)");
  ssubmit->add_option("--partition", subopt.partition, "Slurm partition");
  ssubmit->add_option("--max-running", subopt.max_running, "array tasks at once (%K; 0: no limit)")
      ->capture_default_str();
  ssubmit->add_option("--retries", subopt.retries, "failed attempts retried per case")
      ->capture_default_str()
      ->check(kRetriesRange);
  ssubmit
      ->add_option("--sbatch-arg", subopt.sbatch_args,
                   "an extra sbatch option (repeatable), e.g. --sbatch-arg=--account=X")
      ->allow_extra_args(false);
  ssubmit->add_flag("--dry-run", subopt.dry_run, "print the batch script; write and submit nothing");
  ssubmit->add_option("--solver-command", subopt.solver_command, "")->group("");
  std::string collect_file, collect_db;
  int collect_retries = 2;
  auto* scollect = study_cmd->add_subcommand(
      "collect", "record the run folders that tasks finished (study submit) in the database; safe to repeat");
  scollect->add_option("study", collect_file, "study file (TOML)")->required()->check(CLI::ExistingFile);
  scollect->add_option("--db", collect_db, "results database (SQLite)")->required();
  scollect->add_option("--retries", collect_retries, "as given to study run")
      ->capture_default_str()
      ->check(kRetriesRange);

  // ---- query ----
  auto* query_cmd = app.add_subcommand("query", "read results from a study database");
  query_cmd->require_subcommand(1);
  std::string q_db, q_study, q_group, q_format = "table", q_plot;
  auto* qcurve = query_cmd->add_subcommand("curve", "<<w_p>> and r_acc per group and angle");
  qcurve->add_option("--db", q_db, "results database")->required();
  qcurve->add_option("--study", q_study, "study name")->required();
  qcurve->add_option("--group", q_group, "only this group");
  add_format(qcurve, q_format);
  qcurve->add_option(
      "--plot", q_plot,
      "also draw the curves (like Fig. 14 of the paper): PDF for FILE.pdf, PNG for FILE.png, SVG otherwise");
  bool q_overlay_paper = false;
  qcurve->add_flag("--overlay-paper", q_overlay_paper,
                   "with --plot: also the values the paper states (studies/reference/zeng2021.csv)");
  auto* qvalid = query_cmd->add_subcommand(
      "validation",
      "per finished case: the scene's measured errors against its reference, and the wall time");
  qvalid->add_option("--db", q_db, "results database")->required();
  qvalid->add_option("--study", q_study, "only this study");
  add_format(qvalid, q_format);
  std::string q_reference = "reference";
  auto* qwork = query_cmd->add_subcommand(
      "work-precision", "error of <<w_p>> and r_acc against the reference group, and the run time it cost");
  qwork->add_option("--db", q_db, "results database")->required();
  qwork->add_option("--study", q_study, "study name")->required();
  qwork->add_option("--reference", q_reference, "group holding the reference runs, one per angle")
      ->capture_default_str();
  add_format(qwork, q_format);
  qwork->add_option(
      "--plot", q_plot,
      "also draw |error| against wall time (log-log): PDF for FILE.pdf, PNG for FILE.png, SVG otherwise");
  auto* qcases = query_cmd->add_subcommand("cases", "list cases and their status");
  qcases->add_option("--db", q_db, "results database")->required();
  qcases->add_option("--study", q_study, "only this study");
  add_format(qcases, q_format);

  // Everything after the first `--` is for PETSc; before it, a word the program does not know is
  // a usage error (exit 2), never handed on.
  int cli_argc = argc;
  for (int i = 1; i < argc; ++i)
    if (std::string_view(argv[i]) == "--") {
      cli_argc = i;
      break;
    }
  try {
    app.parse(cli_argc, argv);
  } catch (const CLI::ParseError& e) {
    return usage_error(app, e, cli_argc, argv);
  }
  for (int i = cli_argc + 1; i < argc; ++i) run_opt.petsc_options.emplace_back(argv[i]);
  if (!run->parsed() && cli_argc < argc) {
    std::fprintf(stderr, "error: options after -- are PETSc's and only `case run` takes them\n");
    return boycott::kExitInputError;
  }

  if (srun->parsed()) {
    sopt.progress_live = !study_quiet && isatty(STDERR_FILENO);
    if (study_quiet) sopt.progress_every_s = 0;
    return run_guarded([&] {
      require_db_path(sopt.db_path);
      return boycott::driver::study_run(sopt);
    });
  }
  if (splan->parsed()) return run_guarded([&] { return boycott::driver::study_plan(plan_opt); });
  if (ssubmit->parsed())
    return run_guarded([&] {
      require_db_path(subopt.db_path);
      return boycott::driver::study_submit(subopt);
    });
  if (scollect->parsed())
    return run_guarded([&] {
      require_db_path(collect_db);
      return boycott::driver::study_collect(collect_file, collect_db, collect_retries);
    });
  if (sstatus->parsed())
    return run_guarded([&] {
      require_db_path(status_db);
      return boycott::driver::study_status(status_file, status_db, status_retries,
                                           boycott::driver::parse_listing_format(status_format));
    });
  if (qcurve->parsed())
    return run_guarded([&] {
      const auto fmt_kind = boycott::driver::parse_listing_format(q_format);
      if (q_overlay_paper && q_plot.empty())
        throw boycott::InputError("--overlay-paper draws on the plot: give --plot FILE.svg (or .pdf) too");
      auto db = open_for_query(q_db);
      const auto pts = boycott::driver::query_curve(db, q_study, q_group);
      if (pts.empty())
        throw boycott::InputError(fmt::format("no finished cases of study '{}'{} in '{}'", q_study,
                                              q_group.empty() ? "" : " group '" + q_group + "'", q_db));
      // A plot name with an extension of no format is refused before anything is printed.
      const auto plot_format = q_plot.empty() ? boycott::driver::plot::Format::kSvg
                                              : boycott::driver::plot::format_of_path(q_plot);
      std::fputs(boycott::driver::format_curve(pts, fmt_kind).c_str(), stdout);
      if (!q_plot.empty()) {
        const auto paper = boycott::driver::parse_paper_values(boycott::driver::paper_reference_csv());
        const auto plot = boycott::driver::curve_plot(pts, fmt::format("study {}", q_study),
                                                      q_overlay_paper ? &paper : nullptr, plot_format);
        std::ofstream out(q_plot, std::ios::binary);
        out << plot.data;
        if (!out) throw std::runtime_error(fmt::format("cannot write '{}'", q_plot));
      }
      return 0;
    });
  if (qvalid->parsed())
    return run_guarded([&] {
      const auto fmt_kind = boycott::driver::parse_listing_format(q_format);
      auto db = open_for_query(q_db);
      const auto rows = boycott::driver::query_validation(db, q_study);
      std::fputs(boycott::driver::format_validation(rows, fmt_kind).c_str(), stdout);
      return 0;
    });
  if (qwork->parsed())
    return run_guarded([&] {
      const auto fmt_kind = boycott::driver::parse_listing_format(q_format);
      auto db = open_for_query(q_db);
      const auto wp = boycott::driver::query_work_precision(db, q_study, q_reference);
      if (wp.rows.empty())
        throw boycott::InputError(
            fmt::format("no finished cases of study '{}' outside the reference group '{}' in '{}'", q_study,
                        q_reference, q_db));
      std::fputs(boycott::driver::format_work_precision(wp, fmt_kind).c_str(), stdout);
      if (!q_plot.empty()) {
        const auto plot = boycott::driver::work_precision_plot(
            wp, fmt::format("study {}: error against run time (reference group '{}')", q_study, q_reference),
            boycott::driver::plot::format_of_path(q_plot));
        std::ofstream out(q_plot, std::ios::binary);
        out << plot.data;
        if (!out) throw std::runtime_error(fmt::format("cannot write '{}'", q_plot));
      }
      return 0;
    });
  if (qcases->parsed())
    return run_guarded([&] {
      auto db = open_for_query(q_db);
      std::fputs(boycott::driver::format_cases(boycott::driver::case_states_now(db, q_db, q_study, 2),
                                               boycott::driver::parse_listing_format(q_format))
                     .c_str(),
                 stdout);
      return 0;
    });

  if (run->parsed()) {
    return run_guarded([&] { return boycott::driver::case_run(run_opt, argc, argv); });
  }
  if (check->parsed())
    return run_guarded([&] { return boycott::driver::case_check(check_file, check_sets); });
  if (summarize->parsed())
    return run_guarded([&] { return boycott::driver::case_summarize(summarize_dirs, summarize_db); });
  if (keys->parsed()) return run_guarded([&] { return boycott::driver::case_keys(keys_scene, keys_format); });
  return 0;
}
