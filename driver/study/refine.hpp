#pragma once
// A study's [refine] table (README.md, "Studies"): after a group's listed points finish, `study
// run` and `study submit` add points of `key` around each curve's measured maximum, round by
// round (stats/peak_refine.hpp decides where and when to stop; driver/run/refine_rounds.hpp runs
// the rounds). Here: the table as read, the curves ("series") of a study it refines, and the case
// of an added point, an ordinary case of its group with its own id.
//
// key must be gravity.angle_deg: both objectives are curves over the angle, and r_acc divides by
// the curve's own 90 deg point. A curve is the cases of one group that differ only in the angle
// (and in the keys zipped with it, which `set` gives for the added points): a group that also
// sweeps a viscosity has one curve per viscosity, each refined on its own.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "driver/study/study.hpp"

namespace boycott::driver {

/// Where an added point's value lies on the grid of a tenth of the resolution: readable values
/// (67.25, not 67.2493827), the same on every machine.
double refined_value(double x, double resolution);

/// The curves of a study that [refine] refines, in study order: each group sweeping the key, one
/// per setting of its other swept keys.
struct RefineSeries {
  std::string group;
  std::string setting;  ///< "key=value; ..." of the keys that split the group's curves; "" for none
  std::vector<const StudyCase*> cases;  ///< every case of the curve, replicas and added points too
  const StudyCase* first = nullptr;     ///< its first listed case: what an added point is made from
};
std::vector<RefineSeries> refine_series(const Study& s);

/// The case at key = value on a curve: its first listed case with the key and `set` applied, its
/// swept values those of that case with the key's and set's replaced, checked completely
/// (InputError naming the group and value otherwise), its id computed; replica 0.
StudyCase refined_case(const Study& s, const RefineSeries& series, double value, int round);

/// The study's [refine] table from its text (a stored study's source, say), unset without one;
/// InputError on a malformed one. Reads no group: expand_study_string checks the groups' axes.
std::optional<RefinePlan> read_refine_plan(const std::string& toml_text,
                                           const std::string& origin = "<string>");

}  // namespace boycott::driver
