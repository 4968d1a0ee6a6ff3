#pragma once
// How far a value lies from a reference, relative to it, and the standard error of that relative
// difference from the two values' standard errors (first-order propagation, independent values):
// the error of a work-precision point against its reference run (driver/report/work_precision.hpp).

namespace boycott::stats {

/// A relative difference and its standard error.
struct RelativeDifference {
  double value = 0.0;
  double stderr_of_value = 0.0;  ///< NaN where an error it depends on is
};

/// e = w / w_ref - 1 (w_ref non-zero), with de/dw = 1/w_ref and de/dw_ref = -w/w_ref^2:
/// sigma_e = sqrt((s/w_ref)^2 + (w s_ref/w_ref^2)^2).
RelativeDifference relative_difference(double w, double w_err, double w_ref, double w_ref_err);

/// R - 1 for the ratio of two ratios, R = (w / w90) / (w_ref / w_ref90) (r_acc against the
/// reference's r_acc: the quantity the paper reports, whose error can be far smaller than that of
/// w when a setting shifts all angles alike), with the four standard errors propagated. Every
/// value non-zero.
RelativeDifference ratio_of_ratios_difference(double w, double w_err, double w90, double w90_err,
                                              double w_ref, double w_ref_err, double w_ref90,
                                              double w_ref90_err);

}  // namespace boycott::stats
