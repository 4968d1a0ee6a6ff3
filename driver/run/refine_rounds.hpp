#pragma once
// `study run`'s and `study submit`'s refinement rounds (study key [refine], driver/study/refine.hpp):
// once every case of a curve has finished (done, or failed for good), the rule of
// stats/peak_refine.hpp looks at the curve's points (query_curve's: replicas averaged, covering
// errors) and either adds one point, an ordinary case with its own id, or says why the curve
// stops. The point is recorded with its reason in the database (store_refine.hpp) in the
// transaction that adds its case; a round another driver has recorded is taken from the database
// instead. The rule is a function of the finished points, so the points do not depend on the
// order in which cases finished; a resumed study first re-adds the recorded points
// (add_recorded_refinements) and goes on from there, also after a kill while a point was chosen
// (the transaction either recorded it or left nothing).
#include <set>
#include <string>
#include <vector>

#include "driver/store/database.hpp"
#include "driver/study/study.hpp"

namespace boycott::driver {

/// Appends to `s` the points its database records as added by [refine], with their replicas, in
/// round order per curve; notes on stderr a recorded point that the study no longer makes.
void add_recorded_refinements(Database& db, Study& s);

struct RefineRound {
  std::vector<StudyCase> added;  ///< the new points and their replicas
  int waiting = 0;               ///< curves with a case not finished yet
  /// Curves that stopped, "group (setting): why", and the points added, for the user.
  std::vector<std::string> stopped, adding;
};

/// The next round of the refinement of `s` (which holds the recorded points) from the results in
/// `db`; records each point it adds. `retries` as given to study run (which failures are final).
RefineRound next_refine_round(Database& db, const Study& s, int retries);

/// Prints the round's news on stderr, each stop once per process (`told` remembers them).
void print_refine_round(const RefineRound& round, std::set<std::string>& told);

}  // namespace boycott::driver
