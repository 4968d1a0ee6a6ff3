// The models' wall times a summary reports (ModelTimers): over every attempt of a resumed run,
// the earlier attempts' carried from its checkpoint, and counted from where they are known.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "core/timers.hpp"

namespace boycott {
namespace {

TEST(ModelTimers, CarriedSecondsAreAddedToThisAttemptsPerModel) {
  ModelTimers t;
  t.activate("fluid", "SIMPLE");
  t.add("fluid", 2.0);
  t.add("dem_contacts", 0.5);
  t.carry({{"fluid", 10.0}, {"bed_pouring", 3.0}}, 0.0);
  EXPECT_DOUBLE_EQ(t.seconds("fluid"), 12.0);
  EXPECT_DOUBLE_EQ(t.seconds("dem_contacts"), 0.5);
  EXPECT_DOUBLE_EQ(t.seconds("bed_pouring"), 3.0);  // an earlier attempt's only (a fresh run's phase)
  const std::map<std::string, double> want{{"fluid", 12.0}, {"dem_contacts", 0.5}, {"bed_pouring", 3.0}};
  EXPECT_EQ(t.totals(), want);
  const auto j = t.to_json();
  EXPECT_DOUBLE_EQ(j["fluid"]["wall_time_s"].get<double>(), 12.0);
  EXPECT_EQ(j["fluid"]["detail"], "SIMPLE");
  EXPECT_DOUBLE_EQ(j["bed_pouring"]["wall_time_s"].get<double>(), 3.0);
  EXPECT_EQ(j.size(), 3u);
}

TEST(ModelTimers, AFreshRunCountsFromTheStartAndACarryNamesWhereItsTimesBegin) {
  ModelTimers fresh;
  fresh.add("fluid", 1.0);
  EXPECT_EQ(fresh.counted_from_s(), 0.0);
  EXPECT_DOUBLE_EQ(fresh.seconds("fluid"), 1.0);
  ModelTimers resumed;
  resumed.carry({}, 4.25);  // a checkpoint that recorded no model times: known from 4.25 s on
  resumed.add("fluid", 1.0);
  EXPECT_EQ(resumed.counted_from_s(), 4.25);
  EXPECT_DOUBLE_EQ(resumed.seconds("fluid"), 1.0);
}

}  // namespace
}  // namespace boycott
