#pragma once
// The particles' velocities across the gap (output.velocity_profile_y): for each band of y (the
// bins of pdf_y), over the samples it is fed (every particle at every step of the averaging
// window, as pdf_y counts them), the band's mean particle velocity along the channel w_p and
// across it v_p, the mean fluid velocity the particles see (u_f at the particle, which the drag
// pulls toward: coupler_sample.cpp), their slip w_p - w_f and v_p - v_f, the band's share of the
// particle samples and its share of the particle flux, sum_band w_p / sum_all w_p. The flux shares
// add up to 1 and the bands' means weighted by their sample shares give <<w_p>>, so a change of
// <<w_p>> (the 90 deg gap between runs, say) is split into the bands that carry it.
#include <array>
#include <string>
#include <vector>

#include "stats/running.hpp"

namespace boycott::particles {
struct ParticleStore;
}

namespace boycott::coupling {

class VelocityProfile {
 public:
  /// The sums per band: sample counts, then the velocity components summed (m/s).
  enum Sum { samples, wp, vp, wf, vf, kSums };

  /// Bands over [y0, y0 + width) m.
  VelocityProfile(double y0_m, double width_m, int bands);

  /// One sample of every local particle: its y, velocity (vy, vz) and the fluid velocity it saw
  /// in the step (ufy, ufz).
  void add(const particles::ParticleStore& s);

  /// Every histogram (samples first), for checkpoints and sums over ranks.
  std::vector<stats::Histogram*> all();
  const stats::Histogram& sums(Sum k) const { return sums_[k]; }

  /// The CSV: y_m, sample_share, wp_m_s, vp_m_s, wf_seen_m_s, vf_seen_m_s, slip_w_m_s,
  /// slip_v_m_s, flux_share. A band without samples has nan means and zero shares.
  std::string csv() const;

 private:
  std::array<stats::Histogram, kSums> sums_;
};

}  // namespace boycott::coupling
