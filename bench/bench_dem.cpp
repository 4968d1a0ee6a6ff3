// The dry particle problem of ../shared/bench/liggghts/in.bed on our engine: 15 000 spheres,
// d = 0.6 mm, Table III contacts, theta = 65 deg, dt = 20 us, 0.05 x 0.006 x 0.05 m, Stokes drag
// F = -3 pi mu d v against still water. Inserts, settles 5000 steps untimed, times 20000 steps,
// and prints ns per particle-step (the same measure as the LIGGGHTS script).
// Usage: bench_dem [nsettle] [nrun] [KEY=VALUE ...]   (case keys of dem_only.toml changed, e.g.
//        particles.count=120000 domain.length_x=0.2 domain.height_z=0.1 for the full box)
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "core/case_params.hpp"
#include "core/constants.hpp"
#include "particles/dem_system.hpp"

int main(int argc, char** argv) {
  using namespace boycott;
  const long nsettle = argc > 1 ? std::atol(argv[1]) : 5000;
  const long nrun = argc > 2 ? std::atol(argv[2]) : 20000;
  CaseParams p = parse_case_file(BOYCOTT_SOURCE_DIR "/studies/cases/dem_only.toml");
  for (int a = 3; a < argc; ++a) apply_override(p, argv[a]);
  validate(p);
  auto dc = particles::DemConfig::from_case(p);
  dc.dry = true;  // as the dem_only scene runs it
  particles::DemSystem dem(dc);
  const double r = 0.5 * p.particles.diameter_m;
  dem.insert_random(p.particles.count, r, p.particles.density_kg_m3, {0.0, 0.0, 0.0},
                    {p.domain.length_x_m, p.domain.width_y_m, p.domain.height_z_m}, 15485863);
  auto& s = dem.particles();
  const double beta = 3.0 * kPi * p.fluid.viscosity_pa_s * p.particles.diameter_m;
  for (std::size_t i = 0; i < s.n_local; ++i) s.beta[i] = beta;
  dem.initialize();
  // Whole runs through advance(), as the dem_only scene makes them (kicks fused between steps).
  dem.advance(static_cast<int>(nsettle));
  dem.seconds_force = dem.seconds_neighbor = dem.seconds_integrate = 0.0;
  const auto rebuilds0 = dem.rebuilds(), renewals0 = dem.near_pair_renewals();
  const auto t0 = std::chrono::steady_clock::now();
  dem.advance(static_cast<int>(nrun));
  const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double ps = static_cast<double>(s.n_local) * static_cast<double>(nrun);
  std::printf(
      "boycott: %zu particles, %ld steps, %.2f s (force %.2f, neighbour %.2f in %lld rebuilds, integrate "
      "%.2f), "
      "contacts %lld, list pairs %zu, near pairs %zu in %lld renewals, ns_per_particle_step=%.1f\n",
      s.n_local, nrun, t, dem.seconds_force, dem.seconds_neighbor,
      static_cast<long long>(dem.rebuilds() - rebuilds0), dem.seconds_integrate,
      static_cast<long long>(dem.contact_count()), dem.neighbor_list().pair_count(), dem.near_pair_count(),
      static_cast<long long>(dem.near_pair_renewals() - renewals0), t / ps * 1e9);
  return 0;
}
