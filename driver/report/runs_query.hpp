#pragma once
// `boycott query runs`: per finished run of a study, what its point rests on (the averaging
// window, the error's basis and degrees of freedom, the correlation times the window holds) and
// what it cost (wall time over its attempts, ranks, core-hours).
#include <optional>
#include <string>
#include <vector>

#include "driver/report/listing_format.hpp"
#include "driver/store/database.hpp"
#include "driver/store/store.hpp"

namespace boycott::driver {

/// The study's finished runs in study order. An unknown study name is an InputError.
std::vector<RunRecord> query_runs(Database& db, const std::string& study);

/// Core-hours of a run: its wall time over all attempts times the ranks of the attempt that
/// finished it (a run resumed on another rank count is priced at the last one); unset without both.
std::optional<double> core_hours(const RunRecord& r);
/// CPU core-hours of a run over all its attempts (what it used, where core_hours is what it held:
/// a pause or a machine shared with other work counts there, not here); unset where not recorded.
std::optional<double> cpu_core_hours(const RunRecord& r);

/// Table: one line per run in mm/s, hours and counts, then the totals. CSV and JSON: the raw
/// values in SI units, one row per run (core_hours and cpu_core_hours included), no total.
std::string format_runs(const std::vector<RunRecord>& rows, ListingFormat f);

}  // namespace boycott::driver
