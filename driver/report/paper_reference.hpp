#pragma once
// The values that Zeng et al. (2021) state in their text for the correlation curves of Fig. 11
// and Fig. 14, shipped as studies/reference/zeng2021.csv (with its citation) and embedded in the
// program at build time, for `query curve --plot ... --overlay-paper`.
#include <optional>
#include <string>
#include <vector>

namespace boycott::driver {

struct PaperValue {
  std::string group;                ///< the paper's group, as studies/paper.toml names it
  std::optional<double> angle_deg;  ///< unset: a peak value whose angle the text does not give
  std::string quantity;             ///< "mean_settling_velocity_m_s" or "r_acc"
  double value = 0;
  std::string source;  ///< section and figure
};

/// studies/reference/zeng2021.csv as built into the program.
const std::string& paper_reference_csv();
/// Rows of such a file ('#' lines are comments, then a header); InputError naming the line when
/// one is malformed.
std::vector<PaperValue> parse_paper_values(const std::string& csv_text);

}  // namespace boycott::driver
