#include "driver/report/paper_reference.hpp"

#include <cstdlib>
#include <sstream>

#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott::driver {

namespace {

/// Fields of one CSV line; a field in double quotes may hold commas ("" is a quote).
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      out.back() += '"';
      ++i;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      out.emplace_back();
    } else if (c != '\r') {
      out.back() += c;
    }
  }
  return out;
}

std::optional<double> number(const std::string& s) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0') return std::nullopt;
  return v;
}

}  // namespace

std::vector<PaperValue> parse_paper_values(const std::string& text) {
  std::vector<PaperValue> out;
  std::istringstream in(text);
  std::string line;
  bool header = true;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.empty() || line[0] == '#') continue;
    const auto f = csv_fields(line);
    if (header) {
      if (f.size() < 4 || f[0] != "group" || f[1] != "angle_deg" || f[2] != "quantity" || f[3] != "value")
        throw InputError(fmt::format(
            "paper reference line {}: expected the header group,angle_deg,quantity,value,source", n));
      header = false;
      continue;
    }
    PaperValue v;
    if (f.size() < 4) throw InputError(fmt::format("paper reference line {}: fewer than 4 fields", n));
    v.group = f[0];
    if (!f[1].empty()) {
      v.angle_deg = number(f[1]);
      if (!v.angle_deg)
        throw InputError(fmt::format("paper reference line {}: angle_deg '{}' is not a number", n, f[1]));
    }
    v.quantity = f[2];
    if (v.quantity != "mean_settling_velocity_m_s" && v.quantity != "r_acc")
      throw InputError(
          fmt::format("paper reference line {}: quantity '{}' must be mean_settling_velocity_m_s or r_acc", n,
                      v.quantity));
    const auto value = number(f[3]);
    if (!value) throw InputError(fmt::format("paper reference line {}: value '{}' is not a number", n, f[3]));
    v.value = *value;
    if (f.size() > 4) v.source = f[4];
    out.push_back(std::move(v));
  }
  return out;
}

}  // namespace boycott::driver
