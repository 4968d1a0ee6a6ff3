#pragma once
// The study database: one SQLite file in WAL mode, schema from results_schema/ (embedded), every
// write one BEGIN IMMEDIATE ... COMMIT transaction, so a reader never sees half a case and a
// process killed mid-write leaves the previous state. Queries open it read-only (no WAL switch,
// no migration: a read-only file or mount can be queried); a SQLite file of another program is
// refused before anything is written to it. A write that fails for the storage (disk full, I/O
// error) is a StorageError, not a DatabaseError.
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

struct sqlite3;
struct sqlite3_stmt;

namespace boycott::driver {

class DatabaseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, const std::string& v);
  Statement& bind(int i, double v);
  Statement& bind(int i, std::int64_t v);
  Statement& bind(int i, int v) { return bind(i, static_cast<std::int64_t>(v)); }
  Statement& bind_null(int i);
  template <class T>
  Statement& bind(int i, const std::optional<T>& v) {
    return v ? bind(i, *v) : bind_null(i);
  }
  /// true while there is a row.
  bool step();
  void run() { step(); }
  bool is_null(int col) const;
  std::string text(int col) const;
  double real(int col) const;
  std::int64_t integer(int col) const;

 private:
  sqlite3* db_;
  sqlite3_stmt* st_ = nullptr;
};

enum class OpenMode {
  kCreate,    ///< read-write, created when missing
  kExisting,  ///< read-write, must exist
  kReadOnly,  ///< must exist; opened read-only, never switched to WAL nor migrated
};

class Database {
 public:
  /// Opens `path` (creating it with kCreate), refuses a file that is not this program's database
  /// and one whose user_version is newer than this program knows, then (except kReadOnly)
  /// switches to WAL and migrates up to `target_version` (-1: the newest).
  Database(const std::string& path, OpenMode mode, int target_version = -1);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  static int latest_version();
  int version();
  const std::string& path() const { return path_; }
  sqlite3* handle() { return db_; }

  void exec(const std::string& sql);
  Statement prepare(const std::string& sql) { return Statement(db_, sql); }

  /// Runs fn inside BEGIN IMMEDIATE ... COMMIT; rolls back and rethrows when fn throws.
  template <class F>
  void transaction(F&& fn) {
    exec("BEGIN IMMEDIATE");
    try {
      fn();
      exec("COMMIT");
    } catch (...) {
      exec_noexcept("ROLLBACK");
      throw;
    }
  }

 private:
  /// sqlite3_open_v2 of `name` (the path, or a file: URI) into db_; DatabaseError naming path_.
  void open(const std::string& name, int flags);
  void exec_noexcept(const char* sql);
  /// DatabaseError unless the file is empty or holds this program's tables; reads only.
  void require_own_schema();
  void migrate(int target);
  std::string path_;
  sqlite3* db_ = nullptr;
};

/// Current UTC time, ISO 8601 with milliseconds.
std::string utc_now();

}  // namespace boycott::driver
