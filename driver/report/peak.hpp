#pragma once
// `query peak` as a table, CSV or JSON: per curve, the peak's angle and <<w_p>> with their 68 %
// intervals, r_acc at the peak, the points it rests on and whether it is resolved (peak_query.hpp).
#include <string>
#include <vector>

#include "driver/report/listing_format.hpp"
#include "driver/report/peak_query.hpp"

namespace boycott::driver {

/// Columns (CSV and JSON): group, setting, angle_deg, angle_err_deg (half the interval),
/// angle_low_deg, angle_high_deg, mean_settling_velocity_m_s, error_m_s (half the interval),
/// r_acc, r_acc_err, n_points, n_added, resolved, status, objective, why.
std::string format_peak(const std::vector<PeakRow>& rows, ListingFormat f);

}  // namespace boycott::driver
