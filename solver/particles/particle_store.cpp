#include "particles/particle_store.hpp"

#include <algorithm>

#include "core/constants.hpp"

namespace boycott::particles {

void ParticleStore::add(std::int64_t gid, double px, double py, double pz, double r, double density_kg_m3) {
  const double m = density_kg_m3 * 4.0 / 3.0 * kPi * r * r * r;
  id.push_back(gid);
  for_each_array([](std::vector<double>& a) { a.push_back(0.0); });
  x.back() = px;
  y.back() = py;
  z.back() = pz;
  radius.back() = r;
  mass.back() = m;
  inertia.back() = 0.4 * m * r * r;
  n_local = id.size();
}

void ParticleStore::resize(std::size_t n) {
  id.resize(n);
  for_each_array([n](std::vector<double>& a) { a.resize(n, 0.0); });
  n_local = std::min(n_local, n);
}

void ParticleStore::permute(const std::vector<std::size_t>& order) {
  std::vector<double> tmp(order.size());
  for_each_array([&](std::vector<double>& a) {
    for (std::size_t k = 0; k < order.size(); ++k) tmp[k] = a[order[k]];
    a.swap(tmp);
  });
  std::vector<std::int64_t> tid(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) tid[k] = id[order[k]];
  id.swap(tid);
}

void ParticleStore::keep_increasing(const std::vector<std::size_t>& keep) {
  for_each_array([&](std::vector<double>& a) { compact_increasing(a, keep); });
  compact_increasing(id, keep);
  n_local = std::min(n_local, keep.size());
}

}  // namespace boycott::particles
