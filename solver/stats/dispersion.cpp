#include "stats/dispersion.hpp"

#include <cmath>
#include <limits>

namespace boycott::stats {

double dispersion_index(const std::vector<std::int64_t>& counts) {
  const auto cells = static_cast<double>(counts.size());
  std::int64_t total = 0;
  for (const std::int64_t c : counts) total += c;
  if (counts.size() < 2 || total <= 0) return std::numeric_limits<double>::quiet_NaN();
  const double n = static_cast<double>(total), mean = n / cells, p = 1.0 / cells;
  double s = 0.0;
  for (const std::int64_t c : counts) s += (static_cast<double>(c) - mean) * (static_cast<double>(c) - mean);
  return s / cells / (n * p * (1.0 - p));
}

double dispersion_index_random_sd(std::int64_t particles, std::int64_t cells) {
  if (cells < 2 || particles < 1) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(2.0 * (1.0 - 1.0 / static_cast<double>(particles)) / static_cast<double>(cells - 1));
}

}  // namespace boycott::stats
