#include "driver/store/store_refine.hpp"

#include <chrono>
#include <cstdlib>
#include <optional>
#include <thread>

#include "driver/store/store.hpp"

namespace boycott::driver {
namespace {

constexpr const char* kColumns =
    "study, group_name, setting, round, case_id, key, value, reason, added_at FROM refined_points";

RefinedPoint row_of(const Statement& st) {
  return {st.text(0), st.text(1), st.text(2), static_cast<int>(st.integer(3)), st.text(4), st.text(5),
          st.real(6), st.text(7), st.text(8)};
}

std::optional<RefinedPoint> recorded(Database& db, const RefinedPoint& p) {
  auto st = db.prepare(std::string("SELECT ") + kColumns +
                       " WHERE study = ?1 AND group_name = ?2 AND setting = ?3 AND round = ?4");
  st.bind(1, p.study).bind(2, p.group).bind(3, p.setting).bind(4, p.round);
  if (!st.step()) return std::nullopt;
  return row_of(st);
}

}  // namespace

bool has_refined_points(Database& db) {
  auto st = db.prepare("SELECT COUNT(*) FROM sqlite_master WHERE type = 'table' AND name = 'refined_points'");
  st.step();
  return st.integer(0) > 0;
}

std::vector<RefinedPoint> refined_points(Database& db, const std::string& study) {
  std::vector<RefinedPoint> out;
  if (!has_refined_points(db)) return out;
  auto st =
      db.prepare(std::string("SELECT ") + kColumns + " WHERE study = ?1 ORDER BY group_name, setting, round");
  st.bind(1, study);
  while (st.step()) out.push_back(row_of(st));
  return out;
}

RefinedPoint record_refined_point(Database& db, const RefinedPoint& point, const StudyCase& c) {
  RefinedPoint out = point;
  db.transaction([&] {
    if (const auto other = recorded(db, point)) {
      out = *other;
      return;
    }
    out.added_at = utc_now();
    write_case_rows(db, point.study, c, std::nullopt, out.added_at);
    auto insert = db.prepare(
        "INSERT INTO refined_points(study, group_name, setting, round, case_id, key, value, reason, "
        "added_at) "
        "VALUES (?1,?2,?3,?4,?5,?6,?7,?8,?9)");
    int column = 0;
    for (const std::string* text : {&out.study, &out.group, &out.setting}) insert.bind(++column, *text);
    insert.bind(4, out.round).bind(5, out.case_id).bind(6, out.key).bind(7, out.value);
    insert.bind(8, out.reason).bind(9, out.added_at).run();
    // Test hook: widens the window in which a kill -9 lands while a point is being chosen.
    if (const char* d = std::getenv("BOYCOTT_TEST_REFINE_DELAY_S"))
      std::this_thread::sleep_for(std::chrono::duration<double>(std::atof(d)));
  });
  return out;
}

}  // namespace boycott::driver
