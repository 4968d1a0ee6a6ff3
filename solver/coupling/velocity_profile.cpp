#include "coupling/velocity_profile.hpp"

#include <limits>

#include <fmt/format.h>

#include "particles/particle_store.hpp"

namespace boycott::coupling {

VelocityProfile::VelocityProfile(double y0_m, double width_m, int bands)
    : sums_{stats::Histogram(y0_m, y0_m + width_m, bands), stats::Histogram(y0_m, y0_m + width_m, bands),
            stats::Histogram(y0_m, y0_m + width_m, bands), stats::Histogram(y0_m, y0_m + width_m, bands),
            stats::Histogram(y0_m, y0_m + width_m, bands)} {}

void VelocityProfile::add(const particles::ParticleStore& s) {
  for (std::size_t i = 0; i < s.n_local; ++i) {
    const double y = s.y[i];
    sums_[samples].add(y);
    sums_[wp].add(y, s.vz[i]);
    sums_[vp].add(y, s.vy[i]);
    sums_[wf].add(y, s.ufz[i]);
    sums_[vf].add(y, s.ufy[i]);
  }
}

std::vector<stats::Histogram*> VelocityProfile::all() {
  std::vector<stats::Histogram*> h;
  for (auto& s : sums_) h.push_back(&s);
  return h;
}

std::string VelocityProfile::csv() const {
  std::string text =
      "y_m,sample_share,wp_m_s,vp_m_s,wf_seen_m_s,vf_seen_m_s,slip_w_m_s,slip_v_m_s,flux_share\n";
  const stats::Histogram& n = sums_[samples];
  // Over every sample, those outside the bands too (none where the walls hold the particles).
  const double all_samples = n.total_, all_flux = sums_[wp].total_;
  for (int b = 0; b < n.bins(); ++b) {
    const double count = n.counts_[b];
    double mean[kSums];
    for (int k = wp; k < kSums; ++k)
      mean[k] = count > 0 ? sums_[k].counts_[b] / count : std::numeric_limits<double>::quiet_NaN();
    text += fmt::format("{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", n.bin_center(b),
                        all_samples > 0 ? count / all_samples : 0.0, mean[wp], mean[vp], mean[wf], mean[vf],
                        mean[wp] - mean[wf], mean[vp] - mean[vf],
                        count > 0 && all_flux != 0 ? sums_[wp].counts_[b] / all_flux : 0.0);
  }
  return text;
}

}  // namespace boycott::coupling
