// Placing particles: one at a time, or a random non-overlapping packing of a region.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "particles/dem_system.hpp"
#include "particles/min_image.hpp"

namespace boycott::particles {

void DemSystem::add_particle(std::int64_t gid, double x, double y, double z, double r, double rho) {
  s_.add(gid, x, y, z, r, rho);
  // one of another size ends the contact loops' equal-radius path (initialize() looks again)
  if (s_.radius.back() != uniform_.radius_m || s_.inertia.back() != uniform_.inertia_kg_m2)
    particle_sizes_changed();
  walls_.append_particle();
}

void DemSystem::insert_random(std::int64_t count, double r, double rho, std::array<double, 3> lo,
                              std::array<double, 3> hi, std::uint64_t seed, double gap_m) {
  // Trial placement against a uniform grid of already placed centres (cell >= 2r + gap), so
  // each trial costs O(1); bounded attempts so an overfull request fails instead of hanging.
  std::mt19937_64 rng(seed);
  const double dmin = 2.0 * r + gap_m;
  std::array<int, 3> nc;
  for (int d = 0; d < 3; ++d) nc[d] = std::max(1, static_cast<int>(cfg_.box.len[d] / dmin));
  std::vector<std::vector<std::uint32_t>> cells(static_cast<std::size_t>(nc[0]) * nc[1] * nc[2]);
  auto coord = [&](double p, int d) {
    double f = (p - cfg_.box.lo[d]) / cfg_.box.len[d];
    f -= std::floor(f);
    return std::clamp(static_cast<int>(f * nc[d]), 0, nc[d] - 1);
  };
  for (std::size_t i = 0; i < s_.size(); ++i)
    cells[coord(s_.x[i], 0) + nc[0] * (coord(s_.y[i], 1) + nc[1] * coord(s_.z[i], 2))].push_back(i);
  std::array<std::uniform_real_distribution<double>, 3> U;
  for (int d = 0; d < 3; ++d) U[d] = std::uniform_real_distribution<double>(lo[d], hi[d]);
  std::int64_t next_id = s_.size() ? *std::max_element(s_.id.begin(), s_.id.end()) + 1 : 0;
  const std::int64_t max_attempts = 2000 * count + 100000;
  std::int64_t placed = 0, attempts = 0;
  while (placed < count) {
    if (++attempts > max_attempts)
      throw InputError(
          fmt::format("could not insert {} particles of radius {} m without overlap after {} attempts "
                      "({} placed): the region is too full",
                      count, r, max_attempts, placed));
    const double p[3] = {U[0](rng), U[1](rng), U[2](rng)};
    bool ok = true;
    for (const auto& w : cfg_.walls) {
      const double dist = (p[0] - w.px) * w.nx + (p[1] - w.py) * w.ny + (p[2] - w.pz) * w.nz;
      if (dist < r + 0.5 * gap_m) ok = false;
    }
    const int c[3] = {coord(p[0], 0), coord(p[1], 1), coord(p[2], 2)};
    for (int oz = -1; oz <= 1 && ok; ++oz)
      for (int oy = -1; oy <= 1 && ok; ++oy)
        for (int ox = -1; ox <= 1 && ok; ++ox) {
          const int k[3] = {c[0] + ox, c[1] + oy, c[2] + oz};
          int kk[3];
          bool skip = false;
          for (int d = 0; d < 3; ++d) {
            kk[d] = k[d];
            if (k[d] < 0 || k[d] >= nc[d]) {
              if (!cfg_.box.periodic[d]) skip = true;
              kk[d] = (k[d] + nc[d]) % nc[d];
            }
          }
          if (skip) continue;
          for (std::uint32_t j : cells[kk[0] + nc[0] * (kk[1] + nc[1] * kk[2])]) {
            const double dx = min_image(p[0] - s_.x[j], cfg_.box.period(0), cfg_.box.inv_len(0));
            const double dy = min_image(p[1] - s_.y[j], cfg_.box.period(1), cfg_.box.inv_len(1));
            const double dz = min_image(p[2] - s_.z[j], cfg_.box.period(2), cfg_.box.inv_len(2));
            const double rr = r + s_.radius[j] + gap_m;
            if (dx * dx + dy * dy + dz * dz < rr * rr) {
              ok = false;
              break;
            }
          }
        }
    if (!ok) continue;
    cells[c[0] + nc[0] * (c[1] + nc[1] * c[2])].push_back(static_cast<std::uint32_t>(s_.size()));
    add_particle(next_id++, p[0], p[1], p[2], r, rho);
    ++placed;
  }
}

}  // namespace boycott::particles
