#include "driver/cli/command_line.hpp"

#include <cstdio>

#include "core/error.hpp"
#include "driver/report/terminal_text.hpp"

namespace boycott::driver::cli {

const CLI::Range kCountRange(1, 100000);
const CLI::Range kRetriesRange(0, 1000);

CLI::Option* add_format(CLI::App* cmd, std::string& format) {
  static const CLI::IsMember choices({"table", "csv", "json"});
  return cmd->add_option("--format", format, "table, csv or json")->capture_default_str()->check(choices);
}

CLI::Option* add_retries(CLI::App* cmd, int& retries, const std::string& help) {
  return cmd->add_option("--retries", retries, help)->capture_default_str()->check(kRetriesRange);
}

void require_db_path(const std::string& path) {
  if (path.empty()) throw InputError("--db is empty: name the study database file");
}

Database open_for_query(const std::string& path) {
  require_db_path(path);
  return Database(path, OpenMode::kReadOnly);
}

int run_guarded(const std::function<int()>& fn) {
  try {
    return fn();
  } catch (const DatabaseError& e) {
    // An unusable database (unwritable path, newer schema) is bad input to the driver.
    std::fprintf(stderr, "error: %s\n", printable(e.what()).c_str());
    return kExitInputError;
  } catch (const std::exception& e) {
    // A failed write (disk full, I/O error) keeps the last good checkpoint: StorageError, 74.
    std::fprintf(stderr, "error: %s\n", printable(e.what()).c_str());
    return exit_code_of(e);
  }
}

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
          printable(word).c_str(), names.c_str());
      return kExitInputError;
    }
    level = next;
  }
  std::fprintf(stderr, "error: %s\nRun with --help for more information.\n", printable(e.what()).c_str());
  return kExitInputError;
}

}  // namespace boycott::driver::cli
