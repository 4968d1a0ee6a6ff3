#include "stats/running.hpp"

#include <cmath>
#include <limits>

namespace boycott::stats {

void BatchMeans::add(double x) {
  ++count_;
  total_ += x;
  open_sum_ += x;
  if (++open_n_ < batch_len_) return;
  sums_.push_back(open_sum_);
  open_sum_ = 0.0;
  open_n_ = 0;
  if (static_cast<int>(sums_.size()) >= 2 * min_batches_) {
    std::vector<double> merged(sums_.size() / 2);
    for (std::size_t b = 0; b < merged.size(); ++b) merged[b] = sums_[2 * b] + sums_[2 * b + 1];
    sums_.swap(merged);
    batch_len_ *= 2;
  }
}

double BatchMeans::mean() const {
  return count_ ? total_ / static_cast<double>(count_) : std::numeric_limits<double>::quiet_NaN();
}

double BatchMeans::stderr_of_mean() const {
  const std::size_t B = sums_.size();
  if (B < 4) return std::numeric_limits<double>::quiet_NaN();
  const double L = static_cast<double>(batch_len_);
  double m = 0.0;
  for (double s : sums_) m += s / L;
  m /= static_cast<double>(B);
  double v = 0.0;
  for (double s : sums_) v += (s / L - m) * (s / L - m);
  v /= static_cast<double>(B - 1);
  return std::sqrt(v / static_cast<double>(B));
}

void Histogram::add(double x, double w) {
  total_ += w;
  if (!(x >= lo_ && x < hi_)) {
    outside_ += w;
    return;
  }
  counts_[static_cast<std::size_t>((x - lo_) / (hi_ - lo_) * counts_.size())] += w;
}

std::vector<double> Histogram::density() const {
  std::vector<double> d(counts_.size(), 0.0);
  const double width = (hi_ - lo_) / counts_.size();
  if (total_ <= 0.0) return d;
  for (std::size_t b = 0; b < d.size(); ++b) d[b] = counts_[b] / (total_ * width);
  return d;
}

}  // namespace boycott::stats
