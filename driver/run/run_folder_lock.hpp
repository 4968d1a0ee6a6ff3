#pragma once
// A run folder's lock, <dir>/.lock (flock): held by `study run` for each solver it starts (the
// solver inherits it), by a Slurm task for its solver, and by `case run` itself otherwise, so that
// two runs never write one folder.
#include <filesystem>
#include <optional>
#include <string>

namespace boycott::driver {

/// Takes <dir>/.lock (created when missing) without waiting and returns its descriptor; nullopt
/// while another process (an orphaned solver, another driver) holds it.
std::optional<int> lock_run_folder(const std::filesystem::path& dir);
void unlock_run_folder(int lock_fd);
/// The pid written into <dir>/.lock by the process that took it ("" when none is written).
std::string run_folder_holder(const std::filesystem::path& dir);
/// Set for a solver started under the run folder's lock (start_solver, the Slurm task): the
/// folder whose lock its parent holds for it.
inline constexpr const char* kRunFolderLockedEnv = "BOYCOTT_RUN_FOLDER_LOCKED";
/// Whether <dir>/.lock exists and no process holds it: the solver that held it has exited.
bool run_folder_unheld(const std::filesystem::path& dir);

}  // namespace boycott::driver
