#pragma once
// Small pieces shared by the query reports (curve, validation, work-precision): axis ticks and
// series styles for the plots (drawn by driver/report/plot_cairo.hpp), CSV quoting and aligned text tables.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "driver/store/store.hpp"

namespace boycott::driver::report {

/// Round numbers for ticks over [lo, hi] on a linear axis.
std::vector<double> ticks(double lo, double hi);
/// Decades (and 2, 5 between them when the range spans less than two decades) over [lo, hi] > 0.
std::vector<double> log_ticks(double lo, double hi);

/// Line colour and marker kind of the i-th series, cycling.
const char* color(std::size_t i);
const char* marker_kind(std::size_t i);
/// A CSV field, quoted when it holds a comma, quote or line break (e.g. domain.cells=[200, 6, 100]).
std::string csv_field(const std::string& s);
/// One CSV line of the cells (each through csv_field), ending in a newline.
std::string csv_line(const std::vector<std::string>& cells);

/// A stored number as a CSV cell at full precision (9 significant digits); empty where there is
/// none (absent, or NaN: a figure that could not be computed).
std::string csv_number(const std::optional<double>& v);
/// A stored count as a CSV cell; empty where there is none.
std::string csv_count(const std::optional<std::int64_t>& v);
/// A stored number as JSON: null where there is none (absent or NaN).
nlohmann::json json_number(const std::optional<double>& v);

/// "key=value; key=value" of swept values, "-" when there are none.
std::string join_values(const std::vector<SweptValue>& v);
/// A swept value as JSON: a number when it is one, else its TOML text.
nlohmann::json value_json(const SweptValue& v);

/// A relative error as a signed percentage ("+1.23 %"); small values keep two significant digits.
std::string percent(double rel);

/// A wall time for people: whole seconds from 100 s up, 3 significant digits below.
std::string seconds(double s);

/// A text table whose columns are as wide as their widest cell (widths in code points, so UTF-8
/// in values does not break the alignment).
class TextTable {
 public:
  /// right_aligned[i]: column i holds numbers.
  TextTable(std::vector<std::string> header, std::vector<bool> right_aligned);
  void add(std::vector<std::string> row);
  std::string str() const;
  /// The same rows as CSV (header first).
  std::string csv() const;
  /// The same rows as an array of objects keyed by the header; a number column's cell is a JSON
  /// number, and null where it holds none ("-" or empty).
  nlohmann::json json() const;

 private:
  std::vector<std::string> header_;
  std::vector<bool> right_;
  std::vector<std::vector<std::string>> rows_;
};

}  // namespace boycott::driver::report
