#include "driver/report/report_util.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "core/error.hpp"
#include "driver/report/listing_format.hpp"
#include "driver/report/terminal_text.hpp"

namespace boycott::driver {

ListingFormat parse_listing_format(const std::string& s) {
  if (s == "table") return ListingFormat::kTable;
  if (s == "csv") return ListingFormat::kCsv;
  if (s == "json") return ListingFormat::kJson;
  throw InputError(fmt::format("--format {} is not known: must be table, csv or json", s));
}

}  // namespace boycott::driver

namespace boycott::driver::report {

std::vector<double> ticks(double lo, double hi) {
  const double span = hi - lo;
  const double raw = span / 5.0;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  std::vector<double> t;
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9 * span; v += step)
    t.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
  return t;
}

std::vector<double> log_ticks(double lo, double hi) {
  std::vector<double> t;
  const int d0 = static_cast<int>(std::floor(std::log10(lo))),
            d1 = static_cast<int>(std::ceil(std::log10(hi)));
  // With fewer than two decades in view, decades alone leave the axis nearly unlabelled.
  const bool fine = std::log10(hi / lo) < 2.0;
  for (int d = d0; d <= d1; ++d)
    for (double m : {1.0, 2.0, 5.0}) {
      if (m != 1.0 && !fine) continue;
      const double v = m * std::pow(10.0, d);
      if (v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9)) t.push_back(v);
    }
  return t;
}

namespace {
const char* kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                         "#ff7f0e", "#8c564b", "#e377c2", "#17becf"};
const char* kMarks[] = {"circle", "square", "diamond", "triangle"};

std::size_t utf8_length(const std::string& s) {
  return static_cast<std::size_t>(
      std::count_if(s.begin(), s.end(), [](char c) { return (c & 0xC0) != 0x80; }));
}
}  // namespace

const char* color(std::size_t i) {
  return kColors[i % 8];
}
const char* marker_kind(std::size_t i) {
  return kMarks[i % 4];
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string o = "\"";
  for (char c : s) {
    if (c == '"') o += '"';
    o += c;
  }
  return o + "\"";
}

std::string join_values(const std::vector<SweptValue>& v) {
  if (v.empty()) return "-";
  std::string s;
  for (const auto& x : v) s += fmt::format("{}{}={}", s.empty() ? "" : "; ", x.key, x.display());
  return s;
}

nlohmann::json value_json(const SweptValue& v) {
  return v.value_num ? nlohmann::json(*v.value_num) : nlohmann::json(v.value);
}

std::string csv_number(const std::optional<double>& v) {
  return v && !std::isnan(*v) ? fmt::format("{:.9g}", *v) : std::string();
}
std::string csv_count(const std::optional<std::int64_t>& v) {
  return v ? fmt::format("{}", *v) : std::string();
}
nlohmann::json json_number(const std::optional<double>& v) {
  return v && !std::isnan(*v) ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

std::string percent(double rel) {
  const double p = rel * 100.0;
  // Below 1e-12 a relative error is rounding in the ratio itself (e.g. r_acc of a setting that
  // scales every angle alike), not a difference worth printing.
  if (std::abs(rel) < 1e-12) return "0 %";
  return std::abs(p) >= 0.01 ? fmt::format("{:+.2f} %", p) : fmt::format("{:+.2g} %", p);
}

std::string seconds(double s) {
  return s >= 100 ? fmt::format("{:.0f}", s) : fmt::format("{:.3g}", s);
}

TextTable::TextTable(std::vector<std::string> header, std::vector<bool> right_aligned)
    : header_(std::move(header)), right_(std::move(right_aligned)) {
  right_.resize(header_.size(), false);
}

void TextTable::add(std::vector<std::string> row) {
  row.resize(header_.size());
  rows_.push_back(std::move(row));
}

std::string TextTable::str() const {
  // For a terminal: no cell's control characters reach it (a last error, a swept value).
  std::vector<std::vector<std::string>> rows = rows_;
  for (auto& r : rows)
    for (auto& cell : r) cell = printable(cell);
  std::vector<std::size_t> width(header_.size());
  for (std::size_t c = 0; c < header_.size(); ++c) {
    width[c] = utf8_length(header_[c]);
    for (const auto& r : rows) width[c] = std::max(width[c], utf8_length(r[c]));
  }
  auto line = [&](const std::vector<std::string>& cells) {
    std::string s;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const std::string pad(width[c] - utf8_length(cells[c]), ' ');
      const bool last = c + 1 == cells.size();
      if (c) s += "  ";
      s += right_[c] ? pad + cells[c] : (last ? cells[c] : cells[c] + pad);
    }
    // An empty last cell leaves no padding at the end of the line.
    s.erase(s.find_last_not_of(' ') + 1);
    return s + "\n";
  };
  std::string s = line(header_);
  for (const auto& r : rows) s += line(r);
  return s;
}

std::string csv_line(const std::vector<std::string>& cells) {
  std::string s;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    if (c) s += ',';
    s += csv_field(cells[c]);
  }
  return s + "\n";
}

std::string TextTable::csv() const {
  std::string s = csv_line(header_);
  for (const auto& r : rows_) s += csv_line(r);
  return s;
}

nlohmann::json TextTable::json() const {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : rows_) {
    nlohmann::json o = nlohmann::json::object();
    for (std::size_t c = 0; c < header_.size(); ++c) {
      if (!right_[c]) {
        o[header_[c]] = r[c];
        continue;
      }
      char* end = nullptr;
      const double v = std::strtod(r[c].c_str(), &end);
      o[header_[c]] = !r[c].empty() && end && *end == '\0' ? nlohmann::json(v) : nlohmann::json(nullptr);
    }
    out.push_back(std::move(o));
  }
  return out;
}

}  // namespace boycott::driver::report
