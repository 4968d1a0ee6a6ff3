#include "driver/store/database.hpp"

#include <unistd.h>

#include <sqlite3.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/run_status.hpp"
#include "driver/store/schema_files.hpp"

namespace boycott::driver {

namespace fs = std::filesystem;

namespace {

/// The error of a failed SQLite call: StorageError when the storage failed (disk full, I/O
/// error), DatabaseError otherwise.
[[noreturn]] void sqlite_failure(int rc, const std::string& what) {
  const int primary = rc & 0xff;
  if (primary == SQLITE_FULL || primary == SQLITE_IOERR) throw StorageError(what);
  throw DatabaseError(what);
}

/// A file path as the path of a file: URI (RFC 3986 percent-encoding of what is not unreserved).
std::string uri_path(const std::string& path) {
  std::string out;
  for (const unsigned char c : path) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '_' || c == '.' || c == '~')
      out += static_cast<char>(c);
    else
      out += fmt::format("%{:02X}", c);
  }
  return out;
}

/// The tables every version of this program's schema has.
constexpr const char* kOwnTables[] = {"studies",     "cases",    "study_cases",
                                      "case_values", "attempts", "results"};

}  // namespace

namespace {
/// The tables a statement names after FROM, JOIN, INTO or UPDATE, each with its alias ("results r"
/// or "results AS r"; the name itself where there is none).
std::vector<std::pair<std::string, std::string>> tables_named(const std::string& sql) {
  std::vector<std::string> words;
  std::string w;
  for (char c : sql + " ") {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '_') {
      w += c;
    } else if (!w.empty()) {
      words.push_back(w);
      w.clear();
    }
  }
  auto upper = [](std::string k) {
    for (auto& c : k) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return k;
  };
  static const char* kNotAlias[] = {"WHERE", "JOIN", "LEFT",   "INNER", "CROSS",   "ON",    "GROUP", "ORDER",
                                    "LIMIT", "SET",  "VALUES", "USING", "NATURAL", "UNION", "AS"};
  std::vector<std::pair<std::string, std::string>> out;
  for (std::size_t i = 0; i + 1 < words.size(); ++i) {
    const std::string k = upper(words[i]);
    if (k != "FROM" && k != "JOIN" && k != "INTO" && k != "UPDATE") continue;
    std::string alias = words[i + 1];
    std::size_t a = i + 2;
    if (a < words.size() && upper(words[a]) == "AS") ++a;
    if (a < words.size() && std::none_of(std::begin(kNotAlias), std::end(kNotAlias),
                                         [&](const char* n) { return upper(words[a]) == n; }))
      alias = words[a];
    out.emplace_back(words[i + 1], alias);
  }
  return out;
}
}  // namespace

Statement::Statement(sqlite3* db, const std::string& sql) : db_(db) {
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &st_, nullptr) == SQLITE_OK) return;
  const std::string why = sqlite3_errmsg(db);
  const char* file = sqlite3_db_filename(db, "main");
  // A table or column this version reads is missing: the database's tables are not those of the
  // schema version it records.
  static constexpr const char* kDrift =
      "its tables differ from those of the schema version it records (changed by hand or by another "
      "program?)";
  const std::string where = file && *file ? file : "(in memory)";
  if (why.rfind("no such table: ", 0) == 0)
    throw DatabaseError(fmt::format("database '{}' has no table '{}' that this version reads: {}", where,
                                    why.substr(15), kDrift));
  if (why.rfind("no such column: ", 0) == 0) {
    // "r.mean_settling_velocity_m_s": the table behind the alias; a bare name: the tables read.
    std::string column = why.substr(16), table;
    const auto tables = tables_named(sql);
    if (const auto dot = column.find('.'); dot != std::string::npos) {
      for (const auto& [name, alias] : tables)
        if (alias == column.substr(0, dot)) table = name;
      column = column.substr(dot + 1);
    }
    if (table.empty())
      for (const auto& [name, alias] : tables) table += (table.empty() ? "" : " or ") + name;
    throw DatabaseError(
        fmt::format("database '{}' has no column '{}' in table {} that this version reads: {}", where, column,
                    table, kDrift));
  }
  throw DatabaseError(fmt::format("database: cannot prepare '{}': {}", sql, why));
}
Statement::~Statement() {
  sqlite3_finalize(st_);
}

Statement& Statement::bind(int i, const std::string& v) {
  sqlite3_bind_text(st_, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
  return *this;
}
Statement& Statement::bind(int i, double v) {
  sqlite3_bind_double(st_, i, v);
  return *this;
}
Statement& Statement::bind(int i, std::int64_t v) {
  sqlite3_bind_int64(st_, i, v);
  return *this;
}
Statement& Statement::bind_null(int i) {
  sqlite3_bind_null(st_, i);
  return *this;
}
bool Statement::step() {
  int rc = sqlite3_step(st_);
  // Busy without the busy handler (another process switching the new file to WAL): try again.
  for (int tries = 0; (rc & 0xff) == SQLITE_BUSY && tries < 6000; ++tries) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    sqlite3_reset(st_);
    rc = sqlite3_step(st_);
  }
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  sqlite_failure(rc, fmt::format("database: {}", sqlite3_errmsg(db_)));
}
bool Statement::is_null(int col) const {
  return sqlite3_column_type(st_, col) == SQLITE_NULL;
}
std::string Statement::text(int col) const {
  const auto* t = sqlite3_column_text(st_, col);
  return t ? std::string(reinterpret_cast<const char*>(t)) : std::string();
}
double Statement::real(int col) const {
  return sqlite3_column_double(st_, col);
}
std::int64_t Statement::integer(int col) const {
  return sqlite3_column_int64(st_, col);
}

Database::Database(const std::string& path, OpenMode mode, int target_version) : path_(path) {
  if (path.empty()) throw DatabaseError("the database path is empty");
  struct stat sb {};
  const bool exists = ::stat(path.c_str(), &sb) == 0;
  if (!exists && mode != OpenMode::kCreate) throw DatabaseError(fmt::format("no database at '{}'", path));
  if (exists && S_ISDIR(sb.st_mode))
    throw DatabaseError(fmt::format("--db '{}' is a folder: name the database file in it (e.g. '{}')", path,
                                    (fs::path(path) / "study.sqlite").string()));
  // A query on a database it may write is opened read-write but query-only: SQLite's last
  // connection then folds the write-ahead log back and removes the -wal and -shm files it made,
  // which a read-only connection cannot (and would leave beside the user's database). Where the
  // file or its folder is not writable it is opened read-only (below, the read-only mount).
  const bool query_writable =
      mode == OpenMode::kReadOnly && ::access(path.c_str(), W_OK) == 0 &&
      ::access((fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path()).c_str(),
               W_OK) == 0;
  const int flags = mode == OpenMode::kReadOnly
                        ? (query_writable ? SQLITE_OPEN_READWRITE : SQLITE_OPEN_READONLY)
                        : SQLITE_OPEN_READWRITE | (mode == OpenMode::kCreate ? SQLITE_OPEN_CREATE : 0);
  open(path, flags);
  if (query_writable) sqlite3_exec(db_, "PRAGMA query_only = 1", nullptr, nullptr, nullptr);
  if (mode == OpenMode::kReadOnly &&
      (sqlite3_exec(db_, "SELECT 1 FROM sqlite_master LIMIT 1", nullptr, nullptr, nullptr) & 0xff) ==
          SQLITE_CANTOPEN) {
    // A WAL database on a read-only mount: SQLite cannot create its shared-memory file. With no
    // write-ahead log to read, the file alone is the whole database and cannot change: open it
    // as immutable.
    std::error_code ec;
    const auto wal = fs::file_size(path + "-wal", ec);
    if (!ec && wal > 0)
      throw DatabaseError(
          fmt::format("database '{}' is read-only and has a write-ahead log that cannot be read without "
                      "writing beside it; "
                      "copy the database (with its -wal file) to a writable place to query it",
                      path));
    sqlite3_close(db_);
    db_ = nullptr;
    open(fmt::format("file:{}?immutable=1", uri_path(path)), SQLITE_OPEN_READONLY | SQLITE_OPEN_URI);
  }
  try {
    // Several drivers (or a driver and a query) may share the file: wait for locks, never fail.
    sqlite3_busy_timeout(db_, 30000);
    // Reads only until the file is known to be ours: another program's file is left untouched.
    require_own_schema();
    const int v = version();
    if (v > latest_version())
      throw DatabaseError(fmt::format(
          "database '{}' has schema version {}, newer than this program's {}: use a newer boycott", path, v,
          latest_version()));
    if (mode == OpenMode::kReadOnly) {
      // Version 2 holds every table and column a query reads (3 adds only the identity scheme's
      // record); older ones need the upgrade a `study run` makes.
      if (v < 2)
        throw DatabaseError(
            fmt::format("database '{}' has schema version {}, older than this program's {}: a query does not "
                        "upgrade it; run `boycott study run` on it once",
                        path, v, latest_version()));
    } else {
      exec("PRAGMA journal_mode = WAL");
      exec("PRAGMA synchronous = NORMAL");
      exec("PRAGMA foreign_keys = ON");
      migrate(target_version < 0 ? latest_version() : target_version);
    }
  } catch (const std::runtime_error& e) {
    sqlite3_close(db_);
    db_ = nullptr;
    // SQLite's own words for a path it cannot create are vague; name the file.
    std::string what = e.what();
    if (what.find(path) == std::string::npos) what = fmt::format("database '{}': {}", path, what);
    if (dynamic_cast<const StorageError*>(&e)) throw StorageError(what);
    throw DatabaseError(what);
  }
}

void Database::require_own_schema() {
  // Ours: no table at all (a new file), or every table of the schema. Read with plain
  // statements: a file that is not SQLite fails here too ("file is not a database").
  std::vector<std::string> tables;
  Statement st(db_, "SELECT name FROM sqlite_master WHERE type = 'table'");
  while (st.step()) tables.push_back(st.text(0));
  if (tables.empty() && version() == 0) return;
  std::string missing;
  for (const char* t : kOwnTables)
    if (std::find(tables.begin(), tables.end(), t) == tables.end())
      missing += (missing.empty() ? "" : ", ") + std::string(t);
  if (!missing.empty())
    throw DatabaseError(fmt::format(
        "'{}' is an SQLite file of another program, not a boycott study database (no table {}); it is left "
        "untouched",
        path_, missing));
}

namespace {
/// SQL reached_end(t, end): core/run_status.hpp's definition, for the queries that judge whether a
/// case is done against the study's current time.end; NULL when either is.
void sql_reached_end(sqlite3_context* ctx, int, sqlite3_value** argv) {
  if (sqlite3_value_type(argv[0]) == SQLITE_NULL || sqlite3_value_type(argv[1]) == SQLITE_NULL) {
    sqlite3_result_null(ctx);
    return;
  }
  sqlite3_result_int(ctx, reached_end(sqlite3_value_double(argv[0]), sqlite3_value_double(argv[1])) ? 1 : 0);
}
}  // namespace

void Database::open(const std::string& name, int flags) {
  if (sqlite3_open_v2(name.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
    std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    // SQLite's "unable to open database file" for the common case: a folder that is not there
    // (a new database is made in an existing folder; a mistyped one is not created).
    const auto folder = std::filesystem::path(path_).parent_path();
    std::error_code ec;
    if (!folder.empty() && !std::filesystem::is_directory(folder, ec))
      msg = fmt::format("its folder '{}' does not exist (make it first: mkdir -p {})", folder.string(),
                        folder.string());
    throw DatabaseError(fmt::format("cannot open database '{}': {}", path_, msg));
  }
  if (sqlite3_create_function_v2(db_, "reached_end", 2, SQLITE_UTF8 | SQLITE_DETERMINISTIC, nullptr,
                                 &sql_reached_end, nullptr, nullptr, nullptr) != SQLITE_OK) {
    const std::string msg = sqlite3_errmsg(db_);
    sqlite3_close(db_);
    db_ = nullptr;
    throw DatabaseError(fmt::format("cannot open database '{}': {}", path_, msg));
  }
}

Database::~Database() {
  sqlite3_close(db_);
}

int Database::latest_version() {
  return static_cast<int>(schema_files().size());
}

int Database::version() {
  Statement st(db_, "PRAGMA user_version");
  st.step();
  return static_cast<int>(st.integer(0));
}

void Database::exec(const std::string& sql) {
  char* err = nullptr;
  int rc = SQLITE_OK;
  // The busy timeout does not cover every case: switching to WAL while another process opens the
  // same new file, or WAL recovery, report SQLITE_BUSY at once. Statements run here are safe to
  // repeat after BUSY (BEGIN IMMEDIATE, COMMIT, pragmas; scripts run inside a write transaction).
  for (int tries = 0; tries < 6000; ++tries) {
    sqlite3_free(err);
    err = nullptr;
    rc = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err);
    if ((rc & 0xff) != SQLITE_BUSY) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (rc != SQLITE_OK) {
    std::string msg = err ? err : sqlite3_errmsg(db_);
    sqlite3_free(err);
    sqlite_failure(rc, msg);
  }
}

void Database::exec_noexcept(const char* sql) {
  sqlite3_exec(db_, sql, nullptr, nullptr, nullptr);
}

void Database::migrate(int target) {
  const auto& files = schema_files();
  while (true) {
    // Re-read the version inside each transaction: another process may have migrated meanwhile.
    bool done = false;
    transaction([&] {
      const int v = version();
      if (v >= target) {
        done = true;
        return;
      }
      try {
        exec(files[static_cast<std::size_t>(v)].sql);
      } catch (const DatabaseError& e) {
        throw DatabaseError(
            fmt::format("migration {} failed: {}", files[static_cast<std::size_t>(v)].name, e.what()));
      }
      exec(fmt::format("PRAGMA user_version = {}", v + 1));
    });
    if (done) return;
  }
}

std::string utc_now() {
  const auto now = std::chrono::system_clock::now();
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  return fmt::format("{}.{:03d}Z", buf, static_cast<int>(ms));
}

}  // namespace boycott::driver
