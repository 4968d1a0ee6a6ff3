// The cost model of `study plan` on synthetic runs whose costs are known exactly: what the fit
// recovers, which terms it drops, and the schedule of a study's wall time. The real-run check
// (plan_study.sh) judges the model's form against the solver's measured CPU time; this one
// judges the arithmetic, which a shared machine's timing noise cannot.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "driver/study/cost_model.hpp"

namespace boycott::driver {
namespace {

MeasuredCost run(double particle_steps, double cell_steps, double core_s, const std::string& scene = "s") {
  MeasuredCost m;
  m.case_id = std::string("c");  // (a literal here trips GCC 12's false -Wrestrict)
  m.work.scene = scene;
  m.work.particle_steps = particle_steps;
  m.work.fluid_cell_steps = cell_steps;
  m.core_s = core_s;
  return m;
}

// Exactly linear costs: start 1.5 s, 200 ns per particle-step, 4 us per cell-step.
double exact(double ps, double cs) {
  return 1.5 + 200e-9 * ps + 4e-6 * cs;
}

TEST(CostModel, FitRecoversTheCoefficientsOfExactlyLinearCosts) {
  std::vector<MeasuredCost> runs;
  for (double ps : {1e7, 3e7, 8e7})
    for (double cs : {2e5, 9e5}) runs.push_back(run(ps, cs, exact(ps, cs)));
  const CostModel model(runs);
  EXPECT_EQ(model.basis("s"), "fit to 6 runs");
  CaseWork w{"s", 5e8, 4e6};  // far outside the fitted range: an error in a coefficient shows
  EXPECT_NEAR(model.core_s(w), exact(5e8, 4e6), 1e-9 * exact(5e8, 4e6));
  EXPECT_NEAR(model.core_s(CaseWork{"s", 0.0, 0.0}), 1.5, 1e-9);
}

TEST(CostModel, LeaveOneOutOfExactlyLinearCostsPredictsTheOneLeftOut) {
  std::vector<MeasuredCost> runs;
  for (double ps : {1e7, 3e7, 8e7})
    for (double cs : {2e5, 9e5}) runs.push_back(run(ps, cs, exact(ps, cs)));
  for (std::size_t k = 0; k < runs.size(); ++k) {
    std::vector<MeasuredCost> others;
    for (std::size_t j = 0; j < runs.size(); ++j)
      if (j != k) others.push_back(runs[j]);
    EXPECT_NEAR(CostModel(others).core_s(runs[k].work), runs[k].core_s, 1e-9 * runs[k].core_s) << k;
  }
}

TEST(CostModel, ATermThatWouldBeNegativeIsDroppedAndTheRestRefitted) {
  // Costs that fall with the cell-steps (-100 ns each): a negative coefficient is not a cost, so
  // the fit keeps the start and particle terms only.
  const auto cost = [](double ps, double cs) { return 1.0 + 1e-7 * ps - 1e-7 * cs; };
  std::vector<MeasuredCost> runs = {run(1e7, 1e6, cost(1e7, 1e6)), run(2e7, 3e6, cost(2e7, 3e6)),
                                    run(4e7, 2e6, cost(4e7, 2e6)), run(8e7, 5e5, cost(8e7, 5e5))};
  const CostModel model(runs);
  EXPECT_EQ(model.basis("s"), "fit to 4 runs");
  EXPECT_NEAR(model.core_s(CaseWork{"s", 0.0, 1e9}), model.core_s(CaseWork{"s", 0.0, 0.0}), 1e-12);
  EXPECT_GT(model.core_s(CaseWork{"s", 1e8, 0.0}), model.core_s(CaseWork{"s", 0.0, 0.0}));
}

TEST(CostModel, FewerThanThreeRunsScaleTheDefaultsByTheMeasuredRatio) {
  const CaseWork w{"s", 1e8, 1e6};
  const double by_default = CostModel({}).core_s(w);
  EXPECT_EQ(CostModel({}).basis("s"), "default");
  const CostModel twice({run(1e7, 1e5, 2.0 * CostModel({}).core_s(CaseWork{"s", 1e7, 1e5}))});
  EXPECT_EQ(twice.basis("s"), "default scaled by 1 runs");
  EXPECT_NEAR(twice.core_s(w), 2.0 * by_default, 1e-9 * by_default);
}

TEST(CostModel, ScenesAreFittedApart) {
  std::vector<MeasuredCost> runs;
  for (double ps : {1e7, 3e7, 8e7}) {
    runs.push_back(run(ps, 0.0, 2.0 * exact(ps, 0.0), "a"));
    runs.push_back(run(ps, 0.0, exact(ps, 0.0), "b"));
  }
  const CostModel model(runs);
  const CaseWork a{"a", 5e7, 0.0}, b{"b", 5e7, 0.0};
  EXPECT_NEAR(model.core_s(a), 2.0 * model.core_s(b), 1e-9 * model.core_s(a));
}

// A campaign's angles in one box: every run's fluid work a fixed multiple of its particle work,
// so the runs cannot tell the two costs apart. Costs made exactly as 5 s + 3x the defaults' split:
// the fit recovers it, and a case whose fluid step is cut (twice the cell-steps) costs more by
// 3x the defaults' fluid term, where a free fit would have put everything on one term.
TEST(CostModel, RunsInOneProportionOfFluidToParticleWorkKeepTheDefaultSplit) {
  const auto cost = [](double ps, double cs) {
    return 5.0 + 3.0 * (CostModel::kParticleStepS * ps + CostModel::kCellStepS * cs);
  };
  std::vector<MeasuredCost> runs;
  for (double ps : {1e9, 2e9, 4e9, 8e9}) runs.push_back(run(ps, 0.02 * ps, cost(ps, 0.02 * ps)));
  const CostModel model(runs);
  EXPECT_EQ(model.basis("s"),
            "fit to 4 runs (their particle and fluid work in one proportion: split as the defaults)");
  const CaseWork planned{"s", 3e9, 6e7}, cut{"s", 3e9, 1.2e8};
  EXPECT_NEAR(model.core_s(planned), cost(3e9, 6e7), 1e-9 * cost(3e9, 6e7));
  EXPECT_NEAR(model.core_s(cut) - model.core_s(planned), 3.0 * CostModel::kCellStepS * 6e7, 1e-6);
  // The same runs with one whose proportion differs by just over the separating spread are fitted
  // apart.
  const double wider = 0.02 * 1.01 * CostModel::kSeparatingSpread * 1e9;
  runs.push_back(run(1e9, wider, cost(1e9, wider)));
  EXPECT_EQ(CostModel(runs).basis("s"), "fit to 5 runs");
}

TEST(CostModel, StudyWallTimePlacesTheLongestCasesFirstOnTheSlotThatFreesFirst) {
  // 6, 5, 4, 3 core-s on two single-core slots: {6, 3} and {5, 4} end at 9.
  EXPECT_DOUBLE_EQ(study_wall_s({3.0, 4.0, 5.0, 6.0}, 2, 1), 9.0);
  EXPECT_DOUBLE_EQ(study_wall_s({3.0, 4.0, 5.0, 6.0}, 1, 1), 18.0);
  // Two ranks per case at efficiency 0.9: 18 core-s over 2 * 0.9 cores.
  EXPECT_DOUBLE_EQ(study_wall_s({3.0, 4.0, 5.0, 6.0}, 1, 2), 18.0 / 1.8);
}

// A run whose fluid step was cut (the CFL or the packed-bed limit) did more fluid work than its
// time over dt_cfd: it is fitted against the steps it took. A branch's count includes its
// parent's steps, so there the planned work over its own interval stays.
TEST(CostModel, AFinishedRunIsFittedAgainstTheFluidStepsItTook) {
  const std::string params =
      R"({"scene": "inclined_settling", "particles": {"count": 100}, "domain": {"cells": [10, 2, 5]},
          "time": {"dt_cfd": 0.001, "dt_dem": 0.00002}})";
  bool ok = false;
  const auto planned = measured_cost("a", params, R"({"wall_time_s": 10, "simulated_time_s": 2})", &ok);
  ASSERT_TRUE(ok);
  EXPECT_NEAR(planned.work.fluid_cell_steps, 100.0 * 2000, 1e-6);
  EXPECT_NEAR(planned.work.particle_steps, 100.0 * 2 / 0.00002, 1e-3);
  const auto cut =
      measured_cost("b", params, R"({"wall_time_s": 10, "simulated_time_s": 2, "cfd_steps": 7000})", &ok);
  ASSERT_TRUE(ok);
  EXPECT_NEAR(cut.work.fluid_cell_steps, 100.0 * 7000, 1e-6);
  EXPECT_NEAR(cut.work.particle_steps, planned.work.particle_steps, 1e-3);
  const auto branch = measured_cost(
      "c", params,
      R"({"wall_time_s": 10, "simulated_time_s": 2, "cfd_steps": 7000, "parent": {"time_s": 1}})", &ok);
  ASSERT_TRUE(ok);
  EXPECT_NEAR(branch.work.fluid_cell_steps, 100.0 * 1000, 1e-6);
}

// A particle in an inclined channel's bed touches about two others and the wall; one in a vertical
// channel a third of one: the same particle-steps cost more where gravity pushes them onto a wall.
// A case counts as a bed where gravity's wall-normal share |cos theta| exceeds kBedGravityShare.
TEST(CostModel, ACaseCountsItsParticleStepsAsABedsWhereGravityPushesThemOntoAWall) {
  const auto work = [](double angle_deg) {
    const std::string params = fmt::format(
        R"({{"scene": "inclined_settling", "particles": {{"count": 100}}, "domain": {{"cells": [10, 2, 5]}},
            "time": {{"dt_cfd": 0.001, "dt_dem": 0.00002}}, "gravity": {{"angle_deg": {}}}}})",
        angle_deg);
    return case_work(nlohmann::json::parse(params), 0.0, 2.0);
  };
  for (double a : {15.0, 65.0, 85.0, 95.0, 180.0})
    EXPECT_EQ(work(a).bed_particle_steps, work(a).particle_steps) << a;
  for (double a : {90.0, 88.0, 92.0}) EXPECT_EQ(work(a).bed_particle_steps, 0.0) << a;
  EXPECT_GT(work(65.0).particle_steps, 0.0);
  // A scene without an inclination has no bed term.
  EXPECT_EQ(case_work(nlohmann::json::parse(R"({"scene": "s", "particles": {"count": 100},
                                               "time": {"dt_dem": 0.00002}})"),
                      0.0, 2.0)
                .bed_particle_steps,
            0.0);
}

TEST(CostModel, TheBedTermIsFittedWhereTheRunsHaveBedsAndRunsWithout) {
  // Exactly linear costs with a bed making a particle-step 1.75x as dear.
  const auto cost = [](double ps, double cs, bool bed) { return exact(ps, cs) + (bed ? 150e-9 * ps : 0.0); };
  const auto bed_run = [&](double ps, double cs, bool bed) {
    MeasuredCost m = run(ps, cs, cost(ps, cs, bed));
    m.work.bed_particle_steps = bed ? ps : 0.0;
    return m;
  };
  std::vector<MeasuredCost> runs;
  for (double ps : {1e7, 3e7, 8e7})
    for (double cs : {2e5, 9e5})
      for (bool bed : {false, true}) runs.push_back(bed_run(ps, cs, bed));
  const CostModel model(runs);
  EXPECT_EQ(model.basis("s"), "fit to 12 runs; a bed on a wall makes a particle-step 1.75x as dear");
  CaseWork w{"s", 5e8, 4e6, 5e8};
  EXPECT_NEAR(model.core_s(w), cost(5e8, 4e6, true), 1e-9 * cost(5e8, 4e6, true));
  w.bed_particle_steps = 0.0;
  EXPECT_NEAR(model.core_s(w), cost(5e8, 4e6, false), 1e-9 * cost(5e8, 4e6, false));
  // Runs that are all beds cannot tell the bed term from the particle term: it is not fitted,
  // and the particle term carries the beds' cost.
  std::vector<MeasuredCost> beds;
  for (const auto& m : runs)
    if (m.work.bed_particle_steps > 0) beds.push_back(m);
  const CostModel all_beds(beds);
  EXPECT_EQ(all_beds.basis("s"), "fit to 6 runs");
  EXPECT_NEAR(all_beds.core_s(CaseWork{"s", 5e8, 4e6, 5e8}), cost(5e8, 4e6, true),
              1e-9 * cost(5e8, 4e6, true));
}

// A campaign's runs (one box, one particle count, the angle varied) fit one scale of the defaults'
// split and, with inclined and vertical angles among them, the bed's share on top.
TEST(CostModel, RunsInOneProportionWithBedsAndWithoutFitTheBedsShare) {
  const auto cost = [](double ps, double cs, bool bed) {
    return 5.0 + 3.0 * (CostModel::kParticleStepS * (bed ? 1.8 : 1.0) * ps + CostModel::kCellStepS * cs);
  };
  std::vector<MeasuredCost> runs;
  for (double ps : {1e9, 2e9, 4e9})
    for (bool bed : {false, true}) {
      MeasuredCost m = run(ps, 0.02 * ps, cost(ps, 0.02 * ps, bed));
      m.work.bed_particle_steps = bed ? ps : 0.0;
      runs.push_back(m);
    }
  const CostModel model(runs);
  EXPECT_EQ(
      model.basis("s"),
      "fit to 6 runs (their particle and fluid work in one proportion: split as the defaults); a bed on a "
      "wall makes a particle-step 1.80x as dear");
  EXPECT_NEAR(model.core_s(CaseWork{"s", 3e9, 6e7, 3e9}), cost(3e9, 6e7, true), 1e-9 * cost(3e9, 6e7, true));
  EXPECT_NEAR(model.core_s(CaseWork{"s", 3e9, 6e7, 0.0}), cost(3e9, 6e7, false),
              1e-9 * cost(3e9, 6e7, false));
}

// A run's cost is its CPU time over all attempts where its summary has it (cpu_time_s: blind to
// a pause, steadier than wall time on a shared machine); from builds that recorded only the last
// attempt's, that where the run was done in one, else wall time x ranks.
TEST(CostModel, AFinishedRunCostsItsCpuTimeOverAllAttempts) {
  const std::string params = R"({"scene": "inclined_settling", "particles": {"count": 100},
                                 "time": {"dt_cfd": 0.001, "dt_dem": 0.00002}})";
  const auto cost = [&](const std::string& summary) {
    bool ok = false;
    const auto m = measured_cost("a", params, summary, &ok);
    EXPECT_TRUE(ok) << summary;
    return m.core_s;
  };
  EXPECT_EQ(
      cost(R"({"wall_time_s": 100, "simulated_time_s": 2, "mpi_ranks": 2, "resumed_from_checkpoint": true,
                     "attempt_cpu_time_s": 40, "cpu_time_s": 150})"),
      150.0);
  EXPECT_EQ(
      cost(R"({"wall_time_s": 100, "simulated_time_s": 2, "mpi_ranks": 2, "resumed_from_checkpoint": true,
                     "attempt_cpu_time_s": 40, "cpu_time_s": null})"),
      200.0);
  EXPECT_EQ(
      cost(R"({"wall_time_s": 100, "simulated_time_s": 2, "mpi_ranks": 2, "resumed_from_checkpoint": false,
                     "attempt_cpu_time_s": 180})"),
      180.0);
}

}  // namespace
}  // namespace boycott::driver
