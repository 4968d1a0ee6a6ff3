#pragma once
// Checkpoints of a coupled run: what the next step depends on (the engines' states and the
// run's counters, under the prefixes run., dem., fluid., coupler.) and the scene's own running
// sums, written atomically; resuming from a run folder's newest checkpoint.
#include <filesystem>
#include <functional>
#include <optional>

#include "coupling/coupled_system.hpp"
#include "io/checkpoint_file.hpp"
#include "scenes/run_common.hpp"

namespace boycott::scenes {

/// Collective; w is rank 0's writer (nullptr on the other ranks). The state is the whole run's
/// (all particles, the whole grid), so another number of ranks can resume it.
void save_coupled(io::CheckpointWriter* w, const coupling::CoupledSystem& run);
/// Collective; every rank reads the same file.
void load_coupled(const io::CheckpointReader& r, coupling::CoupledSystem& run);

/// Resumes from the newest checkpoint in `run_dir`, if any: refuses one of another case
/// (CheckpointError, the file left in place), loads this run's state, lets the scene load its
/// own running sums, and cuts the time series back to the checkpoint's time. Returns what the
/// run had already spent (wall time; CPU core-seconds, NaN from a checkpoint of a build that
/// recorded none), or nothing when there is no checkpoint to resume. A run folder without
/// checkpoints given a branch_checkpoint (another run's) starts from that state instead: its
/// particles (with this case's size and density), fluid and time, and fresh statistics of the
/// scene (load_scene is not called); it returns zeros then (a branch pays for its own steps).
std::optional<RunSpent> resume_coupled(coupling::CoupledSystem& run, const std::filesystem::path& run_dir,
                                       bool quiet,
                                       const std::function<void(const io::CheckpointReader&)>& load_scene,
                                       const std::filesystem::path& branch_checkpoint = {});
/// Writes a checkpoint of this run and the scene's running sums (atomically; the newest
/// output.keep_checkpoints are kept), recording what the run has spent so far. Collective;
/// save_scene runs on rank 0 only, so a scene reduces its per-rank sums before.
void checkpoint_coupled(const coupling::CoupledSystem& run, const std::filesystem::path& run_dir,
                        const RunSpent& spent, const std::function<void(io::CheckpointWriter&)>& save_scene);

}  // namespace boycott::scenes
