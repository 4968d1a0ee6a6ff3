#include "scenes/particle_setup.hpp"

#include <algorithm>
#include <cmath>

#include "core/constants.hpp"

namespace boycott::scenes {

namespace {
/// Random sequential insertion stops converging near this solid fraction.
constexpr double kInsertFraction = 0.30;
}  // namespace

void grow_packing(particles::DemSystem& dem, double r0, double r1, double rho, int steps) {
  auto& s = dem.particles();
  auto set_radius = [&](double r) {
    const double m = rho * (4.0 / 3.0) * kPi * r * r * r;
    for (std::size_t i = 0; i < s.n_local; ++i) {
      s.radius[i] = r;
      s.mass[i] = m;
      s.inertia[i] = 0.4 * m * r * r;
    }
    dem.particle_sizes_changed();
  };
  // Strong linear damping toward rest through the implicit drag hook: beta dt / m ~ 0.5.
  const double m1 = rho * (4.0 / 3.0) * kPi * r1 * r1 * r1;
  const double beta = 0.5 * m1 / dem.config().dt_s;
  for (std::size_t i = 0; i < s.n_local; ++i) {
    s.beta[i] = beta;
    s.ufx[i] = s.ufy[i] = s.ufz[i] = 0.0;
  }
  // The neighbour list holds pairs within 2 r + skin of its build; grow in stages of at most a
  // quarter skin, each with a list built for the stage's final radius.
  const double skin = dem.config().skin_m;
  const int stages = std::max(1, static_cast<int>(std::ceil((r1 - r0) / (0.25 * skin))));
  const int per_stage = std::max(1, steps / stages);
  double r_from = r0;
  for (int st = 1; st <= stages; ++st) {
    const double r_to = r0 + (r1 - r0) * st / stages;
    set_radius(r_to);
    dem.initialize();
    for (int k = 1; k <= per_stage; ++k) {
      // Volume grows linearly within the stage, so the solid fraction rises steadily.
      const double f = static_cast<double>(k) / per_stage;
      set_radius(std::cbrt(r_from * r_from * r_from + f * (r_to * r_to * r_to - r_from * r_from * r_from)));
      dem.step();
    }
    r_from = r_to;
  }
  for (int k = 0; k < steps / 4; ++k) dem.step();
  for (std::size_t i = 0; i < s.n_local; ++i) {
    s.beta[i] = 0.0;
    s.vx[i] = s.vy[i] = s.vz[i] = 0.0;
    s.wx[i] = s.wy[i] = s.wz[i] = 0.0;
  }
}

void insert_case_particles(particles::DemSystem& dem, const CaseParams& p) {
  const double r = 0.5 * p.particles.diameter_m;
  const auto& b = dem.config().box;
  std::array<double, 3> lo = b.lo, hi = {b.lo[0] + b.len[0], b.lo[1] + b.len[1], b.lo[2] + b.len[2]};
  const auto seed = static_cast<std::uint64_t>(p.seed);
  if (p.particles.insertion == "bed") {
    constexpr double kLooseFraction = 0.3;
    const double h = p.particles.count * p.particle_volume_m3() / (kLooseFraction * b.len[0] * b.len[2]);
    hi[1] = std::min(hi[1], b.lo[1] + h + 2.0 * r);
  }
  if (p.particles.insertion == "packed") {
    const double ap = p.solid_fraction();
    const double r0 = ap > kInsertFraction ? r * std::cbrt(kInsertFraction / ap) : r;
    dem.insert_random(p.particles.count, r0, p.particles.density_kg_m3, lo, hi, seed);
    if (r0 < r) {
      dem.initialize();
      grow_packing(dem, r0, r, p.particles.density_kg_m3, 4000);
    }
    return;
  }
  dem.insert_random(p.particles.count, r, p.particles.density_kg_m3, lo, hi, seed);
}

}  // namespace boycott::scenes
