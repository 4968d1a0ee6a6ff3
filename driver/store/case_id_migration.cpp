#include "driver/store/case_id_migration.hpp"

#include <map>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/case_params.hpp"
#include "core/error.hpp"

namespace fs = std::filesystem;

namespace boycott::driver {

namespace {

std::optional<int> stored_version(Database& db) {
  auto st = db.prepare("SELECT value FROM meta WHERE key = 'case_id_version'");
  if (!st.step()) return std::nullopt;
  return std::stoi(st.text(0));
}

struct OldCase {
  std::string id, new_id, params_json;
};

/// Every case of the database with its id under the current identity version.
std::vector<OldCase> cases_with_new_ids(Database& db) {
  std::vector<OldCase> cases;
  {
    auto st = db.prepare("SELECT id, params_json FROM cases ORDER BY created_at, id");
    while (st.step()) cases.push_back({st.text(0), "", st.text(1)});
  }
  for (auto& c : cases) {
    CaseParams p;
    try {
      p = case_from_json(nlohmann::json::parse(c.params_json));
      validate(p);
    } catch (const std::exception& e) {
      throw InputError(
          fmt::format("case {} in the database cannot be read for the migration to case identity "
                      "version {}: {}",
                      c.id, kCaseIdVersion, e.what()));
    }
    c.new_id = case_id(p);
    c.params_json = to_json(p).dump();
  }
  return cases;
}

/// Two old cases are one now (they differed in time.end or output only): the older row stays;
/// this one's result joins it unless the case has one already (then the one that reached further
/// in time is kept). Its memberships, values and attempts follow in move_case_rows.
void merge_case(Database& db, const OldCase& c) {
  db.prepare("DELETE FROM cases WHERE id = ?1").bind(1, c.id).run();
  auto keep = db.prepare(
      "SELECT (SELECT average_to_s FROM results WHERE case_id = ?1), (SELECT average_to_s FROM results "
      "WHERE case_id = ?2)");
  keep.bind(1, c.new_id).bind(2, c.id);
  keep.step();
  const bool take_this = !keep.is_null(1) && (keep.is_null(0) || keep.real(1) > keep.real(0));
  db.prepare("DELETE FROM results WHERE case_id = ?1").bind(1, take_this ? c.new_id : c.id).run();
}

/// The rows that name the case by its old id name it by its new one.
void move_case_rows(Database& db, const OldCase& c, const fs::path& runs_root) {
  for (const char* sql :
       {"UPDATE OR IGNORE study_cases SET case_id = ?2 WHERE case_id = ?1",
        "DELETE FROM study_cases WHERE case_id = ?1",
        "UPDATE OR IGNORE case_values SET case_id = ?2 WHERE case_id = ?1",
        "DELETE FROM case_values WHERE case_id = ?1", "UPDATE results SET case_id = ?2 WHERE case_id = ?1",
        "UPDATE attempts SET case_id = ?2 WHERE case_id = ?1",
        "UPDATE refined_points SET case_id = ?2 WHERE case_id = ?1"})
    db.prepare(sql).bind(1, c.id).bind(2, c.new_id).run();
  // The attempts' folders moved with the case (unless it merged into another's).
  if (!fs::exists(runs_root / c.id))
    db.prepare("UPDATE attempts SET run_dir = replace(run_dir, ?1, ?2) WHERE case_id = ?2")
        .bind(1, c.id)
        .bind(2, c.new_id)
        .run();
}

}  // namespace

IdMigration migrate_case_ids(Database& db, const fs::path& runs_root) {
  IdMigration m;
  if (stored_version(db).value_or(1) >= kCaseIdVersion) return m;
  const std::vector<OldCase> cases = cases_with_new_ids(db);
  // Folders first (see the header): each old folder becomes its new id's, unless that exists
  // (a case that merged with another: its folder stays under the old name).
  for (const auto& c : cases) {
    if (c.new_id == c.id) continue;
    const fs::path from = runs_root / c.id, to = runs_root / c.new_id;
    if (fs::exists(from) && !fs::exists(to)) {
      fs::rename(from, to);
      ++m.folders;
    }
  }
  db.transaction([&] {
    // The references follow the ids within the transaction; the constraints are checked at COMMIT.
    db.exec("PRAGMA defer_foreign_keys = ON");
    std::map<std::string, std::string> first_of;  // new id -> the first old case that took it
    for (const auto& c : cases) {
      if (c.new_id == c.id) continue;
      ++m.cases;
      const bool merged = first_of.count(c.new_id) > 0 || [&] {
        auto st = db.prepare("SELECT 1 FROM cases WHERE id = ?1");
        st.bind(1, c.new_id);
        return st.step();
      }();
      if (!merged) {
        first_of[c.new_id] = c.id;
        db.prepare("UPDATE cases SET id = ?2, params_json = ?3 WHERE id = ?1")
            .bind(1, c.id)
            .bind(2, c.new_id)
            .bind(3, c.params_json)
            .run();
      } else {
        ++m.merged;
        merge_case(db, c);
      }
      move_case_rows(db, c, runs_root);
    }
    db.prepare("INSERT OR REPLACE INTO meta(key, value) VALUES ('case_id_version', ?1)")
        .bind(1, std::to_string(kCaseIdVersion))
        .run();
  });
  return m;
}

}  // namespace boycott::driver
