#pragma once
// `boycott stats mean`: the product's rules for the mean of a series and its error
// (solver/stats/window_error.hpp, transient.hpp) on any columns a user has, as a run's
// summary.json states them for <w_p>.
#include <optional>
#include <string>
#include <vector>

#include "driver/report/listing_format.hpp"
#include "driver/report/series_table.hpp"

namespace boycott::driver::report {

/// Where the average starts: all rows (unset), from a time (s; a row index where the file has no
/// time column), or where the start-up transient is detected to end ("auto").
struct AverageFrom {
  std::optional<double> from;
  bool automatic = false;
};
/// "auto" or a number; InputError for anything else.
AverageFrom parse_average_from(const std::string& s);

/// One column's mean and error. Times are in s where the file has a time column, else in rows.
struct SeriesMean {
  std::string name;
  bool velocity = false;  ///< the name ends in _m_s: the error is error_m_s
  std::size_t samples = 0;
  double average_from = 0.0, mean = 0.0, error = 0.0, stderr_of_mean = 0.0, dof = 0.0;
  std::string basis;  ///< stats::error_method_name
  int batches = 0;
  double tau_int = 0.0, tau_int_upper = 0.0, correlation_times = 0.0;
  double transient_end = 0.0;  ///< NaN: no estimate
  std::vector<std::string> warnings;
};

/// The columns `wanted` (all numeric ones when empty; InputError naming an unknown one) averaged
/// from `from` (InputError when that leaves fewer than 8 rows).
std::vector<SeriesMean> series_means(const SeriesTable& t, const std::vector<std::string>& wanted,
                                     const AverageFrom& from);

/// The rows as an aligned table, CSV or JSON (an array of objects, NaN as null).
std::string format_series_means(const std::vector<SeriesMean>& rows, ListingFormat format, bool timed);

}  // namespace boycott::driver::report
