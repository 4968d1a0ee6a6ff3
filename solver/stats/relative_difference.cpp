#include "stats/relative_difference.hpp"

#include <cmath>

namespace boycott::stats {

RelativeDifference relative_difference(double w, double w_err, double w_ref, double w_ref_err) {
  return {w / w_ref - 1.0, std::hypot(w_err / w_ref, w * w_ref_err / (w_ref * w_ref))};
}

RelativeDifference ratio_of_ratios_difference(double w, double w_err, double w90, double w90_err,
                                              double w_ref, double w_ref_err, double w_ref90,
                                              double w_ref90_err) {
  const double R = (w / w90) * (w_ref90 / w_ref);
  const double dw = w_err * w_ref90 / (w90 * w_ref);
  const double dw90 = R * w90_err / w90, dwr = R * w_ref_err / w_ref, dwr90 = R * w_ref90_err / w_ref90;
  return {R - 1.0, std::sqrt(dw * dw + dw90 * dw90 + dwr * dwr + dwr90 * dwr90)};
}

}  // namespace boycott::stats
