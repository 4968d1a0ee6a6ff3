#pragma once
// What a case costs, for `study plan` and the estimate `study run` prints before it starts. Per
// scene, core-seconds = a + b * particle-steps + c * fluid cell-steps + d * bed particle-steps,
// fitted to the finished runs of the database (relative least squares, terms that would be
// negative dropped; runs whose two kinds of work stand in one proportion fit a and one scale of the
// defaults' b : c); with fewer than three finished runs of a scene, the default coefficients
// below, scaled by the mean ratio of the measured to the predicted cost of those there are.
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace boycott::driver {

/// The work of a run: from its resolved parameters (params.json), over [from_s, to_s].
struct CaseWork {
  std::string scene;
  double particle_steps = 0.0;    ///< particles x DEM steps
  double fluid_cell_steps = 0.0;  ///< fluid cells x CFD steps (at dt_cfd, the CFL limit aside)
  /// The particle-steps again where gravity has a component onto a wall (an inclined channel:
  /// the particles gather into a bed on the lower wall, and a particle in the bed touches about
  /// two others and the wall, where one in a vertical channel touches a third of one): the
  /// contact work's extra cost, fitted where a scene's runs have both kinds. 0 otherwise.
  double bed_particle_steps = 0.0;
};
/// A wall-normal share of gravity, |cos theta| (g = (0, -g cos theta, -g sin theta)), above this
/// counts as making a bed: at 87 deg the paper's 0.6 mm sand (0.09 m/s alone) drifts onto the
/// lower wall at ~5 mm/s and crosses its 6 mm channel in ~1.3 s of a 10-20 s run; closer to the
/// vertical the bed forms late and the case counts as vertical.
inline constexpr double kBedGravityShare = 0.05;
CaseWork case_work(const nlohmann::json& params, double from_s, double to_s);

/// One finished run: its work (its fluid cell-steps at the steps it took, `cfd_steps`) and what
/// it cost in core-seconds (its CPU time over all attempts, cpu_time_s; from older builds the CPU
/// time of a run done in one attempt, else wall time x ranks).
struct MeasuredCost {
  std::string case_id;
  CaseWork work;
  double core_s = 0.0;
};
/// The finished runs from their params.json and summary.json texts; unreadable ones are skipped.
MeasuredCost measured_cost(const std::string& case_id, const std::string& params_json,
                           const std::string& summary_json, bool* ok);

class CostModel {
 public:
  /// Defaults for a database with fewer than 3 finished runs, calibrated on three whole runs of
  /// the inclined_settling scene on this 2-core machine (docs/performance.md, "Estimates against
  /// runs"): the demo's 2 s cases (2 400 particles), the reduced base case (15 000, 6 s) and the
  /// full base case (120 000, 20 s). The particles' and the fluid's shares keep the full case's
  /// profile (210 : 74.5 ns per particle-step at 50 DEM steps per CFD step and one particle per
  /// cell), scaled by one factor, the geometric mean of measured / predicted over the three; each
  /// is then predicted within 1.5x. The cost per particle-step grows with the box (cache) and
  /// with the sliding bed's contacts, which a model linear in the work cannot follow further.
  static constexpr double kStartS = 2.0, kParticleStepS = 76e-9, kCellStepS = 1.35e-6;
  /// Runs whose fluid-to-particle work ratios all lie within this factor fit one scale on the
  /// defaults' split instead of the two costs apart (they cannot separate them).
  static constexpr double kSeparatingSpread = 1.5;

  explicit CostModel(const std::vector<MeasuredCost>& finished);
  /// Core-seconds of this work.
  double core_s(const CaseWork& w) const;
  /// How the scene's coefficients were found: "fit to N runs", "default scaled by N runs", "default".
  std::string basis(const std::string& scene) const;

 private:
  struct Coefficients {
    double start_s = kStartS, particle_step_s = kParticleStepS, cell_step_s = kCellStepS;
    double bed_particle_step_s = 0.0;
    int runs = 0;
    bool fitted = false;
    bool one_proportion = false;  ///< fitted as one scale on the defaults' split
  };
  std::map<std::string, Coefficients> by_scene_;
};

/// Wall time of running these cases' core-seconds on `jobs` slots of `ranks` cores each, longest
/// first on the slot that frees first (parallel efficiency 0.9 per doubling of ranks).
double study_wall_s(std::vector<double> core_s, int jobs, int ranks);
double ranks_efficiency(int ranks);

}  // namespace boycott::driver
