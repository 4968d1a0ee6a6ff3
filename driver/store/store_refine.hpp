#pragma once
// The study database's record of the points [refine] added (results_schema/005_refinement.sql):
// which curve, which round, which case, and why. Each function that writes is one transaction; the
// SQL lives in store_refine.cpp.
#include <string>
#include <vector>

#include "driver/store/database.hpp"
#include "driver/study/study.hpp"

namespace boycott::driver {

/// One added point of a curve (study, group, setting).
struct RefinedPoint {
  std::string study, group, setting;
  int round = 0;
  std::string case_id, key;
  double value = 0.0;
  std::string reason, added_at;
};

/// Whether the database has the table (a database of schema 4 or older, opened read-only by a
/// query, has none: no point was added to it).
bool has_refined_points(Database& db);

/// The study's added points, by group, setting and round.
std::vector<RefinedPoint> refined_points(Database& db, const std::string& study);

/// Records `point` and its case `c` (as register_study records a case, at the study's next
/// position) in one transaction, unless its curve's round is recorded already (by another driver
/// on the same database): the row the database holds, either way.
RefinedPoint record_refined_point(Database& db, const RefinedPoint& point, const StudyCase& c);

}  // namespace boycott::driver
