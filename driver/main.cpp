// boycott: the command-line front end. Subcommands follow design brief section 7.
#include <csignal>
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/error.hpp"
#include "core/version.hpp"
#include "driver/case_commands.hpp"

namespace {

int run_guarded(const std::function<int()>& fn) {
  try {
    return fn();
  } catch (const boycott::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return boycott::kExitInputError;
  } catch (const boycott::PhysicsError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return boycott::kExitPhysicsError;
  } catch (const boycott::CheckpointError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return boycott::kExitCheckpointError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return boycott::kExitFailure;
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"boycott: unresolved CFD-DEM of proppant settling in inclined narrow channels, and its study driver"};
  app.require_subcommand(1);
  app.set_version_flag("--version", fmt::format("boycott {}+{}", boycott::kVersion, boycott::kGitRevision));

  auto* case_cmd = app.add_subcommand("case", "run or check a single case");
  case_cmd->require_subcommand(1);

  boycott::driver::CaseRunOptions run_opt;
  auto* run = case_cmd->add_subcommand("run", "run (or resume) one case; PETSc options may follow '--'");
  run->add_option("case", run_opt.case_file, "case file (TOML)")->required()->check(CLI::ExistingFile);
  run->add_option("--out", run_opt.out_dir, "run folder (params, checkpoints, outputs)")->required();
  run->add_option("--set", run_opt.overrides, "override a key: section.key=value")->take_all();
  run->add_flag("--quiet", run_opt.quiet, "no progress output");
  run->allow_extras();

  std::string check_file;
  std::vector<std::string> check_sets;
  auto* check = case_cmd->add_subcommand("check", "validate a case and print its pre-flight report");
  check->add_option("case", check_file, "case file (TOML)")->required()->check(CLI::ExistingFile);
  check->add_option("--set", check_sets, "override a key: section.key=value")->take_all();

  auto* keys = case_cmd->add_subcommand("keys", "list every case key and its default");

  CLI11_PARSE(app, argc, argv);

  if (run->parsed()) {
    run_opt.petsc_options = run->remaining();
    return run_guarded([&] { return boycott::driver::case_run(run_opt, argc, argv); });
  }
  if (check->parsed()) return run_guarded([&] { return boycott::driver::case_check(check_file, check_sets); });
  if (keys->parsed()) return run_guarded([&] { return boycott::driver::case_keys(); });
  return 0;
}
