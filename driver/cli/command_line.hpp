#pragma once
// The pieces every subcommand of the `boycott` command line shares: how a subcommand is set up
// and run, the options that mean the same everywhere (counts, --retries, --format, --db), and how
// errors become exit codes. Each group's subcommands: case_cli.cpp, study_cli.cpp, query_cli.cpp,
// stats_cli.cpp.
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "driver/store/database.hpp"

namespace boycott::driver::cli {

/// One subcommand: its parser, and what runs when the command line named it (the exit code).
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

/// Counts a user gives (jobs, ranks): whole numbers in a range CLI11 names in its message.
extern const CLI::Range kCountRange;
/// --retries: failed attempts retried per case.
extern const CLI::Range kRetriesRange;

/// --format table|csv|json, the same choices in every listing command, listed in help.
CLI::Option* add_format(CLI::App* cmd, std::string& format);
/// --retries (as `study run` takes it) with its default shown.
CLI::Option* add_retries(CLI::App* cmd, int& retries, const std::string& help);

/// --db names a file: an empty one would be SQLite's private temporary database.
void require_db_path(const std::string& path);
/// A query's database: read-only (a read-only file or mount can be queried; nothing migrated).
Database open_for_query(const std::string& path);

/// fn's exit code; an exception is printed as "error: ..." and becomes its exit code (a database
/// that cannot be used is bad input, 2; a failed write 74).
int run_guarded(const std::function<int()>& fn);

/// A command line the program did not understand: CLI11's message, naming the word, and exit 2
/// (--help and --version exit 0).
int usage_error(CLI::App& app, const CLI::ParseError& e, int argc, char** argv);

/// `boycott case run|check|keys|summarize`; what follows `--` goes to *petsc_options of case run,
/// which `petsc_options` is set to point at.
std::vector<Command> setup_case_commands(CLI::App& app, int argc, char** argv,
                                         std::vector<std::string>** petsc_options);
/// `boycott study run|status|plan|submit|collect`.
std::vector<Command> setup_study_commands(CLI::App& app);
/// `boycott query curve|peak|validation|work-precision|cases`.
std::vector<Command> setup_query_commands(CLI::App& app);
/// `boycott stats mean`.
std::vector<Command> setup_stats_commands(CLI::App& app);

}  // namespace boycott::driver::cli
