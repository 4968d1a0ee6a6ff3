#include "coupling/force_budget.hpp"

#include <fmt/format.h>

#include "particles/particle_store.hpp"

namespace boycott::coupling {

ForceBudget::ForceBudget(double y0_m, double width_m, int bands)
    : exposure_(y0_m, y0_m + width_m, bands), impulse_(kTerms, exposure_), prepared_(kTerms, exposure_) {}

void ForceBudget::commit(const particles::ParticleStore& s, double dt_s, double gravity_y_m_s2) {
  for (int t = 0; t < kTerms; ++t) {
    stats::Histogram& p = prepared_[t];
    for (std::size_t b = 0; b < p.counts_.size(); ++b) impulse_[t].counts_[b] += p.counts_[b] * dt_s;
    impulse_[t].outside_ += p.outside_ * dt_s;
    impulse_[t].total_ += p.total_ * dt_s;
    p = stats::Histogram(p.lo_, p.hi_, p.bins());
  }
  // The kick: (m + m_add) dv = dt (F_contacts + F_ext + m g) + J, F_ext holding the prepared
  // fluid forces, so the contact impulse (walls included) is what the rest leaves.
  for (std::size_t i = 0; i < s.n_local; ++i) {
    const double y = s.y[i], m = s.mass[i], ma = s.madd[i], dv = s.vy[i] - s.v0y[i];
    const double j_drag = s.drag_jy[i], j_grav = dt_s * m * gravity_y_m_s2;
    exposure_.add(y, dt_s);
    impulse_[drag].add(y, j_drag);
    impulse_[added_mass].add(y, -ma * dv);
    impulse_[gravity].add(y, j_grav);
    impulse_[net].add(y, m * dv);
    // Walls are subtracted band by band when the table is written (the DEM bins them itself).
    impulse_[particle_contacts].add(y, (m + ma) * dv - dt_s * s.ext_y[i] - j_grav - j_drag);
  }
}

std::vector<stats::Histogram*> ForceBudget::all() {
  std::vector<stats::Histogram*> h{&exposure_};
  for (auto& i : impulse_) h.push_back(&i);
  return h;
}

std::string ForceBudget::csv(double buoyant_weight_n) const {
  std::string text = "y_m,particle_density_1_m";
  for (int t = 0; t < kForces; ++t) text += fmt::format(",{}_n", kNames[t]);
  for (int t = 0; t < kForces; ++t) text += fmt::format(",{}_per_weight", kNames[t]);
  text += ",re_p,re_w\n";
  const auto dens = exposure_.density();
  for (int b = 0; b < exposure_.bins(); ++b) {
    const double e = exposure_.counts_[b];
    double mean[kTerms];
    for (int t = 0; t < kTerms; ++t) mean[t] = e > 0 ? impulse_[t].counts_[b] / e : 0.0;
    mean[particle_contacts] -= mean[walls];
    text += fmt::format("{:.9g},{:.9g}", exposure_.bin_center(b), dens[b]);
    for (int t = 0; t < kForces; ++t) text += fmt::format(",{:.9g}", mean[t]);
    for (int t = 0; t < kForces; ++t) text += fmt::format(",{:.9g}", mean[t] / buoyant_weight_n);
    text += fmt::format(",{:.9g},{:.9g}\n", mean[re_p], mean[re_w]);
  }
  return text;
}

}  // namespace boycott::coupling
