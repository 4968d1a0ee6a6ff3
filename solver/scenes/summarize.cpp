#include "scenes/summarize.hpp"

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/case_params.hpp"
#include "core/error.hpp"
#include "core/run_status.hpp"
#include "core/scene_specs.hpp"
#include "core/version.hpp"
#include "scenes/summary_statistics.hpp"
#include "stats/precision_target.hpp"

namespace boycott::scenes {

stats::StepSeries read_step_series(const io::CheckpointReader& r) {
  stats::StepSeries s;
  if (r.has("stats.wp_before")) {
    s.before = r.doubles("stats.wp_before");
    s.before_dt = r.doubles("stats.wp_before_dt");
    s.window_dt = r.doubles("stats.wp_dt");
  } else {
    s.before_whole = s.dt_whole = false;
  }
  return s;
}

void write_step_series(io::CheckpointWriter& w, const stats::StepSeries& s) {
  w.put("stats.wp_before", s.before);
  w.put("stats.wp_before_dt", s.before_dt);
  w.put("stats.wp_dt", s.window_dt);
}

nlohmann::json resummarize_run(const std::filesystem::path& run_dir) {
  const auto summary_path = run_dir / "summary.json";
  std::ifstream in(summary_path);
  if (!in)
    throw InputError(
        fmt::format("{}: no summary.json (the run has not ended; `case run` resumes it)", run_dir.string()));
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: summary.json is not JSON ({})", summary_path.string(), e.what()));
  }
  // Only a scene that keeps <w_p>'s whole per-step series in its checkpoints can be recomputed.
  const std::string scene = j.value("scene", "");
  std::vector<std::string> keeping;
  for (const auto& spec : scene_specs())
    if (spec.detects_transient) keeping.push_back(spec.name);
  if (std::find(keeping.begin(), keeping.end(), scene) == keeping.end())
    throw InputError(
        fmt::format("{}: a {} run; case summarize recomputes <<w_p>> of {} runs, whose checkpoints "
                    "keep its per-step series",
                    run_dir.string(), scene.empty() ? "(no scene named)" : scene, fmt::join(keeping, ", ")));
  const auto ckpt = io::latest_checkpoint(run_dir);
  if (!ckpt) throw InputError(fmt::format("{}: no checkpoint to recompute from", run_dir.string()));
  const io::CheckpointReader r(*ckpt);
  if (!r.has("stats.wp_series"))
    throw InputError(
        fmt::format("{}: its checkpoint {} keeps no <w_p> series (an earlier build): nothing to "
                    "recompute from",
                    run_dir.string(), ckpt->filename().string()));
  const CaseParams p = case_from_json(nlohmann::json::parse(r.string("case_json")));
  const stats::StepSeries steps = read_step_series(r);
  const auto window = r.doubles("stats.wp_series");
  const double now_s = r.scalar("run.time_s");
  if (j.contains("warnings")) {
    nlohmann::json kept = nlohmann::json::array();
    for (const auto& w : j["warnings"])
      if (!w.is_string() || !is_settling_statistics_warning(w.get<std::string>())) kept.push_back(w);
    j["warnings"] = kept;
  }
  // A run its precision target stopped: the plan its first stage fixed (runs stopped by builds
  // before the two-stage rule kept none and get the window's own error).
  stats::PrecisionTarget target(p.time.target_rel_error);
  if (r.has("stats.target")) target.from_state(r.doubles("stats.target"));
  const stats::TwoStagePlan* plan = j.value("status", "") == kStatusConverged ? &target.plan() : nullptr;
  const stats::ChosenWindow chosen = averaging_window(p.time.average_from, steps, window, now_s, plan);
  const stats::WindowError w = stats::window_error(chosen.window, chosen.from_s, now_s, plan);
  report_settling_statistics(j, chosen.steps, chosen.window, w, true);
  if (p.time.average_from.automatic) {
    j["mean_settling_velocity_m_s"] = w.e.mean;
    j["samples_averaged"] = static_cast<std::int64_t>(chosen.window.size());
  }
  j["summarized_by_version"] = kVersion;
  return j;
}

}  // namespace boycott::scenes
