// boycott: the command-line front end; its subcommands are set up and run by case_cli.cpp,
// study_cli.cpp, query_cli.cpp and stats_cli.cpp (for users: README.md, "Running a case", "Studies",
// "Outputs").
#include <cstdio>
#include <string_view>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/version.hpp"
#include "driver/cli/command_line.hpp"

int main(int argc, char** argv) {
  namespace cli = boycott::driver::cli;
  CLI::App app{
      "boycott: unresolved CFD-DEM of proppant settling in inclined narrow channels, and its study driver"};
  app.require_subcommand(1);
  app.footer(
      "Exit codes: 0 done; 2 bad input or usage; 3 unphysical state; 4 unusable checkpoint or run folder; 74 "
      "storage error (nothing lost); 75 interrupted (run again: it resumes from its checkpoint, or starts "
      "over in a scene that keeps none); 1 other "
      "failure.");
  app.set_version_flag("--version", fmt::format("boycott {}+{}", boycott::kVersion, boycott::kGitRevision));

  std::vector<std::string>* petsc_options = nullptr;
  std::vector<cli::Command> commands = cli::setup_case_commands(app, argc, argv, &petsc_options);
  for (auto& c : cli::setup_study_commands(app)) commands.push_back(std::move(c));
  for (auto& c : cli::setup_query_commands(app)) commands.push_back(std::move(c));
  for (auto& c : cli::setup_stats_commands(app)) commands.push_back(std::move(c));
  const CLI::App* case_run = commands.front().app;

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
    return cli::usage_error(app, e, cli_argc, argv);
  }
  for (int i = cli_argc + 1; i < argc; ++i) petsc_options->emplace_back(argv[i]);
  if (!case_run->parsed() && cli_argc < argc) {
    std::fprintf(stderr, "error: options after -- are PETSc's and only `case run` takes them\n");
    return boycott::kExitInputError;
  }
  for (const auto& c : commands)
    if (c.app->parsed()) return cli::run_guarded(c.run);
  return 0;
}
