#pragma once
// Particle data, structure of arrays. Local particles occupy [0, n_local); ghost copies (periodic
// or MPI halo images, later) follow in [n_local, size()). Ids are global and never reused, so
// contact histories and checkpoints refer to particles independently of storage order.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace boycott::particles {

/// a <- (a[keep[0]], a[keep[1]], ...) in place, for strictly increasing keep: element k is read
/// from keep[k] >= k, which no earlier write has touched. The prefix where keep[k] == k stays.
template <class T>
void compact_increasing(std::vector<T>& a, const std::vector<std::size_t>& keep) {
  if (a.empty()) return;  // an array the run does not use
  std::size_t k = 0;
  while (k < keep.size() && keep[k] == k) ++k;
  for (; k < keep.size(); ++k) a[k] = a[keep[k]];
  a.resize(keep.size());
}

struct ParticleStore {
  std::size_t n_local = 0;

  std::vector<std::int64_t> id;
  std::vector<double> x, y, z;                ///< position, m
  std::vector<double> vx, vy, vz;             ///< velocity, m/s
  std::vector<double> wx, wy, wz;             ///< angular velocity, rad/s
  std::vector<double> fx, fy, fz;             ///< contact force, N (recomputed every step)
  std::vector<double> tx, ty, tz;             ///< contact torque, N m
  std::vector<double> radius, mass, inertia;  ///< m, kg, kg m^2 (solid sphere: 2/5 m r^2)

  // Coupling hook: (m + m_add) dv/dt = F_contact + F_ext + m g + beta (u_f - v), drag implicit.
  std::vector<double> ext_x, ext_y, ext_z;  ///< explicit external force, N
  std::vector<double> beta;                 ///< implicit linear drag coefficient, kg/s
  std::vector<double> ufx, ufy, ufz;        ///< fluid velocity the drag pulls toward, m/s
  std::vector<double> madd;                 ///< added mass, kg
  /// Drag impulse beta (u_f - v) dt actually applied by the kicks since the coupling last reset
  /// it, N s: what the fluid must receive back so that momentum is exchanged exactly.
  std::vector<double> drag_jx, drag_jy, drag_jz;
  // Kept for the coupling over one CFD step, here so that they move with a particle that
  // changes rank mid-step: the velocity at the step's start (m/s), the explicit reaction owed to
  // the fluid (N), and the pressure-gradient plus viscous force of the last sampling (N).
  std::vector<double> v0x, v0y, v0z;
  std::vector<double> react_x, react_y, react_z;
  std::vector<double> fpv_x, fpv_y, fpv_z;

  std::size_t size() const { return id.size(); }
  /// Arrays that for_each_array visits (a checkpoint stores them in this order; the coupling
  /// arrays were added last, so a checkpoint of 29 arrays is an older one).
  static constexpr int kArrays = 38;
  /// Keeps the first n particles (drops ghost copies, for instance).
  void resize(std::size_t n);

  /// Appends a local particle at rest (before any ghost is created).
  void add(std::int64_t gid, double px, double py, double pz, double r, double density_kg_m3);

  /// Reorders every per-particle array by `order` (new index k holds old particle order[k]).
  /// An order of fewer particles than stored puts those first; resize() then drops the rest.
  void permute(const std::vector<std::size_t>& order);

  /// Keeps particles keep[0] < keep[1] < ... (strictly increasing), in that order, and drops the
  /// rest: the same result as permute(keep) then resize(keep.size()), but in place (each array is
  /// read and written once, from the first particle that moves, with no copy allocated).
  void keep_increasing(const std::vector<std::size_t>& keep);

  template <class F>
  void for_each_array(F&& f) {
    for (auto* a :
         {&x,     &y,    &z,       &vx,      &vy,      &vz,     &wx,      &wy,      &wz,      &fx,
          &fy,    &fz,   &tx,      &ty,      &tz,      &radius, &mass,    &inertia, &ext_x,   &ext_y,
          &ext_z, &beta, &ufx,     &ufy,     &ufz,     &madd,   &drag_jx, &drag_jy, &drag_jz, &v0x,
          &v0y,   &v0z,  &react_x, &react_y, &react_z, &fpv_x,  &fpv_y,   &fpv_z})
      f(*a);
  }
};

}  // namespace boycott::particles
