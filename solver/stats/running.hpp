#pragma once
// Statistics kept while a run goes: time averages of correlated series by batch means, and
// histograms. The standard error of the mean of an autocorrelated series is underestimated by
// sigma/sqrt(N); batch means (Flyvbjerg & Petersen 1989, Law & Kelton) group the series into B
// consecutive batches long enough to be nearly independent and use the scatter of the batch means:
// SE = sd(batch means)/sqrt(B). Batch means never checks that a batch is longer than the
// correlation time; autocorrelation_error() (stats/autocorrelation.hpp) estimates the correlation
// time itself from the whole series. Both accumulators' whole state is plain numbers (for
// checkpoints: io/state_io.hpp).
#include <cstdint>
#include <vector>

namespace boycott::stats {

/// Incremental batch-means estimator with O(B) state: samples fill batches of size `batch_len`;
/// when 2B batches are full, neighbouring batches are merged and batch_len doubles, so any
/// series length ends with between B and 2B batches. Its whole state is plain numbers (for
/// checkpoints).
class BatchMeans {
 public:
  explicit BatchMeans(int min_batches = 16) : min_batches_(min_batches) {}
  void add(double x);
  std::int64_t count() const { return count_; }
  double mean() const;
  /// Standard error of the mean from the complete batches (NaN with fewer than 4 batches).
  double stderr_of_mean() const;
  int batches() const { return static_cast<int>(sums_.size()); }

  // State, for checkpoints.
  int min_batches_;
  std::int64_t count_ = 0;
  std::int64_t batch_len_ = 1;
  double total_ = 0.0;
  std::vector<double> sums_;  ///< sums of the complete batches
  double open_sum_ = 0.0;     ///< the batch being filled
  std::int64_t open_n_ = 0;
};

/// Fixed-range histogram normalised as a probability density (values outside are counted apart).
class Histogram {
 public:
  Histogram(double lo, double hi, int bins) : lo_(lo), hi_(hi), counts_(bins, 0.0) {}
  void add(double x, double weight = 1.0);
  std::vector<double> density() const;
  double bin_center(int b) const { return lo_ + (b + 0.5) * (hi_ - lo_) / counts_.size(); }
  int bins() const { return static_cast<int>(counts_.size()); }
  double lo_, hi_;
  std::vector<double> counts_;
  double outside_ = 0.0;
  double total_ = 0.0;
};

}  // namespace boycott::stats
