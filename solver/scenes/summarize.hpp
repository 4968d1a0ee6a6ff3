#pragma once
// `boycott case summarize`: a finished inclined_settling run's statistics of <<w_p>> recomputed
// from the per-step series its last checkpoint keeps, with the rules of this build (errors that
// cover, the transient, the time-weighted mean), so runs finished by an older build get them.
#include <filesystem>

#include <nlohmann/json.hpp>

#include "io/checkpoint_file.hpp"
#include "scenes/summary_statistics.hpp"

namespace boycott::scenes {

/// The step series an inclined_settling checkpoint keeps beside <w_p>'s window series (the samples
/// before the window, the step lengths); marked incomplete for checkpoints of builds without them.
stats::StepSeries read_step_series(const io::CheckpointReader& r);
/// ... and written.
void write_step_series(io::CheckpointWriter& w, const stats::StepSeries& s);

/// The run's summary.json with the statistics of <<w_p>> recomputed and their warnings replaced
/// (not written). Throws InputError when the folder holds no finished inclined_settling run or
/// its last checkpoint keeps no <w_p> series (builds before the autocorrelation error).
nlohmann::json resummarize_run(const std::filesystem::path& run_dir);

}  // namespace boycott::scenes
