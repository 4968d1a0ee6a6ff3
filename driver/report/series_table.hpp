#pragma once
// A CSV of series as `boycott stats mean` reads it: a header of column names, then rows of
// numbers; the first column is the time (s) when it is named `t` or `time_s`. Whatever a user's
// file gets wrong is refused with one sentence (InputError): no numeric column, a ragged row, a
// NaN or infinity, fewer than 8 rows, a time that does not increase.
#include <optional>
#include <string>
#include <vector>

namespace boycott::driver::report {

struct SeriesTable {
  std::optional<std::vector<double>> time_s;  ///< the first column, when it is the time
  std::vector<std::string> names;             ///< the numeric columns but the time, in file order
  std::vector<std::vector<double>> columns;   ///< their values, one vector per name
};

/// The cells of one line of such a file (no quoting: names and numbers), trimmed of spaces and of
/// a trailing carriage return.
std::vector<std::string> series_cells(const std::string& line);

/// The table in `text` (the file `path`, named in messages). A column with any cell that is not a
/// number (text, an empty cell) is not numeric and is left out; a cell that reads as NaN or
/// infinity is refused (a gap in a series makes every statistic of it meaningless).
SeriesTable parse_series_table(const std::string& text, const std::string& path);

}  // namespace boycott::driver::report
