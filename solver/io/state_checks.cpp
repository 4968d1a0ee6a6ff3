#include "io/state_checks.hpp"

#include <cmath>
#include <unordered_set>

#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott::io {

namespace {

[[noreturn]] void refuse(const std::string& file, const std::string& dataset, const std::string& check) {
  throw CheckpointError(fmt::format("checkpoint {}: dataset '{}' fails the check: {}", file, dataset, check));
}

void require_finite(const std::vector<double>& a, const std::string& file, const std::string& dataset) {
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!std::isfinite(a[i]))
      refuse(file, dataset, fmt::format("value {} at index {} is not finite", a[i], i));
}

}  // namespace

void check_state(const particles::DemState& s, const StateBounds& b, const std::string& file,
                 const std::string& prefix) {
  particles::ParticleStore store = s.store;  // for_each_array walks a mutable store
  const std::size_t n = store.id.size();
  if (store.n_local > n)
    refuse(file, prefix + "n_local", fmt::format("{} local particles of {} stored", store.n_local, n));
  std::unordered_set<std::int64_t> seen;
  seen.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (store.id[i] < 0)
      refuse(file, prefix + "id", fmt::format("particle id {} at index {} is negative", store.id[i], i));
    if (!seen.insert(store.id[i]).second)
      refuse(file, prefix + "id",
             fmt::format("particle id {} is stored twice (ids must be unique)", store.id[i]));
  }
  int k = 0;
  store.for_each_array([&](std::vector<double>& a) {
    const std::string name = fmt::format("{}array{:02d}", prefix, k++);
    if (a.size() != n) refuse(file, name, fmt::format("{} values for {} particles", a.size(), n));
    require_finite(a, file, name);
  });
  const std::array<const std::vector<double>*, 3> pos = {&store.x, &store.y, &store.z};
  for (int d = 0; d < 3; ++d) {
    const double L = b.length_m[d];
    if (!(L > 0.0)) continue;
    for (std::size_t i = 0; i < n; ++i) {
      const double c = (*pos[d])[i];
      // Periodic: wrapped once per neighbour-list build, so within one length of the box.
      const double slack = b.periodic[d] ? L : store.radius[i];
      if (c < -slack || c > L + slack)
        refuse(file, fmt::format("{}array{:02d}", prefix, d),
               fmt::format("particle {} has {} = {} m, outside the box [0, {}] m{}", store.id[i], "xyz"[d], c,
                           L, b.periodic[d] ? " by more than one box length" : " by more than its radius"));
    }
  }
  for (const auto& [name, a] : {std::pair{"ref_x", &s.ref_x},
                                {"ref_y", &s.ref_y},
                                {"ref_z", &s.ref_z},
                                {"pair_hx", &s.pair_hx},
                                {"pair_hy", &s.pair_hy},
                                {"pair_hz", &s.pair_hz},
                                {"wall_h", &s.wall_h}})
    require_finite(*a, file, prefix + name);
  for (const auto& [name, a] : {std::pair{"pair_id_a", &s.pair_id_a}, {"pair_id_b", &s.pair_id_b}})
    for (std::size_t i = 0; i < a->size(); ++i)
      if ((*a)[i] < 0) refuse(file, prefix + name, fmt::format("id {} at index {} is negative", (*a)[i], i));
  if (!std::isfinite(s.time_s) || s.time_s < 0.0)
    refuse(file, prefix + "time_s", fmt::format("time {} s is not a finite time >= 0", s.time_s));
}

void check_state(const fluid::FluidState& s, const std::string& file, const std::string& prefix) {
  for (std::size_t f = 0; f < s.fields.size(); ++f)
    require_finite(s.fields[f], file, fmt::format("{}field.{:02d}", prefix, f));
  // FluidState's layout: u, v, w at n and n-1, p, then alpha_f at n, n-1 and n+1, nu_t.
  if (s.fields.size() == 11)
    for (std::size_t f = 7; f <= 9; ++f)
      for (std::size_t i = 0; i < s.fields[f].size(); ++i) {
        const double a = s.fields[f][i];
        if (!(a > 0.0 && a <= 1.0))
          refuse(file, fmt::format("{}field.{:02d}", prefix, f),
                 fmt::format("fluid fraction {} at index {} is outside (0, 1]", a, i));
      }
  for (const auto& [name, v] : {std::pair{"time_s", s.time_s},
                                {"dt_prev_s", s.dt_prev_s},
                                {"mean_pressure_gradient_pa_m", s.mean_pressure_gradient_pa_m}})
    if (!std::isfinite(v)) refuse(file, prefix + name, fmt::format("value {} is not finite", v));
}

void check_finite(const std::vector<std::vector<double>>& arrays, const std::string& file,
                  const std::string& prefix) {
  for (std::size_t k = 0; k < arrays.size(); ++k)
    require_finite(arrays[k], file, fmt::format("{}{:02d}", prefix, k));
}

}  // namespace boycott::io
