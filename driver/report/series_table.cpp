#include "driver/report/series_table.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott::driver::report {
namespace {

// The number a cell holds, or none (text, empty); NaN for "nan", infinity for "inf".
std::optional<double> number_of(const std::string& cell) {
  if (cell.empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(cell.c_str(), &end);
  if (end != cell.c_str() + cell.size()) return std::nullopt;
  return v;
}

}  // namespace

std::vector<std::string> series_cells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) {
    const auto a = cell.find_first_not_of(" \t\r"), b = cell.find_last_not_of(" \t\r");
    cells.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
  }
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

SeriesTable parse_series_table(const std::string& text, const std::string& path) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || series_cells(line).empty())
    throw InputError(fmt::format("'{}' has no header line of column names", path));
  const std::vector<std::string> header = series_cells(line);
  std::vector<std::vector<std::optional<double>>> raw(header.size());
  for (std::size_t row = 2; std::getline(in, line); ++row) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const auto cells = series_cells(line);
    if (cells.size() != header.size())
      throw InputError(fmt::format("row {} of '{}' has {} cells where the header names {} columns", row, path,
                                   cells.size(), header.size()));
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const auto v = number_of(cells[c]);
      if (v && !std::isfinite(*v))
        throw InputError(fmt::format("row {} of '{}' holds {} in column '{}': a series with gaps has no mean",
                                     row, path, cells[c], header[c]));
      raw[c].push_back(v);
    }
  }
  SeriesTable t;
  const bool timed = !header.empty() && (header[0] == "t" || header[0] == "time_s");
  for (std::size_t c = 0; c < header.size(); ++c) {
    std::vector<double> values;
    for (const auto& v : raw[c])
      if (v) values.push_back(*v);
    if (values.size() != raw[c].size() || values.empty()) continue;  // not numeric
    if (c == 0 && timed) {
      for (std::size_t k = 1; k < values.size(); ++k)
        if (!(values[k] > values[k - 1]))
          throw InputError(fmt::format("the time in '{}' does not increase at row {}", path, k + 2));
      t.time_s = std::move(values);
    } else {
      t.names.push_back(header[c]);
      t.columns.push_back(std::move(values));
    }
  }
  if (t.columns.empty()) throw InputError(fmt::format("'{}' has no numeric column (besides the time)", path));
  if (t.columns.front().size() < 8)
    throw InputError(fmt::format("'{}' has {} rows: the error of a mean needs 8 samples at least", path,
                                 t.columns.front().size()));
  return t;
}

}  // namespace boycott::driver::report
