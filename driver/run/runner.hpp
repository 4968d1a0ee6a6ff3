#pragma once
// `boycott study run|status`: runs the missing cases of a study as child processes
// (`boycott case run CASE --out DIR`, optionally under mpirun), records every attempt and result
// in the study database, and resumes, skips or retries cases from what the database says.
// study_run sets up and reports; the parts: scheduler.hpp (queue, slots, retries, stop),
// solver_process.hpp (locks, fork/exec, signals, reaping), recording.hpp (run folder to rows),
// progress.hpp (live display). None of them holds SQL: they read and write through store.hpp.
#include <string>
#include <vector>

#include "driver/report/listing_format.hpp"
#include "driver/run/scheduler.hpp"
#include "driver/store/database.hpp"
#include "driver/store/store.hpp"

namespace boycott::driver {

/// Exit code: 0 all cases done, 75 stopped by a signal, 1 some case failed for good, 74 stopped
/// after storage errors in a row (Scheduler::kStorageFailuresToStop).
int study_run(const StudyRunOptions& opt);
/// case_states, with an open attempt whose run folder no process holds (and no Slurm task owns)
/// as interrupted: the one vocabulary of `study status` and `query cases`.
std::vector<CaseState> case_states_now(Database& db, const std::string& db_path, const std::string& study,
                                       int retries);
/// case_states_now for the cases as `study` (its file) now sets them: a done case whose result
/// falls short of a time.end raised in the file since the last `study run` is pending (`study
/// status`, `study plan`).
std::vector<CaseState> case_states_for(Database& db, const std::string& db_path, const Study& study,
                                       int retries);
/// The study's cases and their states (pending without a database; none is created).
int study_status(const std::string& study_file, const std::string& db_path, int retries,
                 ListingFormat format = ListingFormat::kTable);

}  // namespace boycott::driver
