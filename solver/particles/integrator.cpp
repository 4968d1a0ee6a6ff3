// Velocity Verlet (paper Eqs. 4-6) with the coupling hook: drag implicit in the half kicks,
// added mass in the mass matrix, and the predicted velocities the contact forces see.
#include <algorithm>
#include <array>
#include <chrono>
#include <type_traits>
#include <vector>

#include "core/timers.hpp"
#include "particles/dem_system.hpp"
#include "particles/displacement_bound.hpp"

namespace boycott::particles {

namespace {
/// The half kick (see DemSystem::kick), all components in one pass so that m, m_add and beta are
/// read once and (M + h beta) is inverted once per particle; restrict-qualified parameters let
/// GCC vectorise it. Predict: also write 2 v_new - v_old to p; Track: accumulate the drag
/// impulse in J; Wet: read the fluid arrays (F_ext, u_f, m_add), which a dry kick leaves out.
/// Fused (between two steps of a sub-cycle): the closing half kick of a step, then the opening
/// one of the next with its prediction, then its drift x += dt v, in one pass instead of three.
/// Both kicks see the same forces, so the acceleration and (M + h beta)^-1 are formed once; each
/// value is the same expression, in the same order, as in the separate passes: the results are
/// bit for bit theirs. Record (fused only): v_z after the closing kick to rz.
template <bool Predict, bool Track, bool Wet, bool Fused, bool Record = false>
void kick_loop(std::size_t i0, std::size_t n, double h, double dt, double gx, double gy, double gz,
               const double* __restrict m, const double* __restrict ma, const double* __restrict b,
               double* __restrict fx, double* __restrict fy, double* __restrict fz,
               const double* __restrict ex, const double* __restrict ey, const double* __restrict ez,
               const double* __restrict ux, const double* __restrict uy, const double* __restrict uz,
               double* __restrict vx, double* __restrict vy, double* __restrict vz, double* __restrict Jx,
               double* __restrict Jy, double* __restrict Jz, double* __restrict px, double* __restrict py,
               double* __restrict pz, double* __restrict x, double* __restrict y, double* __restrict z,
               double* __restrict rz) {
  static_assert(!Fused || Predict, "the fused pass opens a step: it predicts");
  static_assert(!Record || Fused, "only a fused pass has the end of a step inside it");
  for (std::size_t i = i0; i < n; ++i) {
    // Dry (!Wet): F_ext, u_f and m_add are zero and not read (DemConfig::dry).
    const double M = Wet ? m[i] + ma[i] : m[i], bi = b[i], inv_D = 1.0 / (M + h * bi);
    double ax = fx[i], ay = fy[i], az = fz[i];
    if constexpr (Wet) {
      ax += ex[i];
      ay += ey[i];
      az += ez[i];
    }
    ax += m[i] * gx;
    ay += m[i] * gy;
    az += m[i] * gz;
    if constexpr (Wet) {
      ax += bi * ux[i];
      ay += bi * uy[i];
      az += bi * uz[i];
    }
    double v0x = vx[i], v0y = vy[i], v0z = vz[i];
    double jx = 0.0, jy = 0.0, jz = 0.0;
    if constexpr (Track) jx = Jx[i], jy = Jy[i], jz = Jz[i];
    if constexpr (Fused) {
      // The closing half kick of the step that ends here.
      v0x = (M * v0x + h * ax) * inv_D;
      v0y = (M * v0y + h * ay) * inv_D;
      v0z = (M * v0z + h * az) * inv_D;
      if constexpr (Record) rz[i] = v0z;
      if constexpr (Track) {
        jx += h * bi * (ux[i] - v0x);
        jy += h * bi * (uy[i] - v0y);
        jz += h * bi * (uz[i] - v0z);
      }
    }
    const double v1x = (M * v0x + h * ax) * inv_D;
    const double v1y = (M * v0y + h * ay) * inv_D;
    const double v1z = (M * v0z + h * az) * inv_D;
    vx[i] = v1x;
    vy[i] = v1y;
    vz[i] = v1z;
    if constexpr (Track) {
      Jx[i] = jx + h * bi * (ux[i] - v1x);
      Jy[i] = jy + h * bi * (uy[i] - v1y);
      Jz[i] = jz + h * bi * (uz[i] - v1z);
    }
    if constexpr (Predict) {
      px[i] = 2.0 * v1x - v0x;
      py[i] = 2.0 * v1y - v0y;
      pz[i] = 2.0 * v1z - v0z;
    }
    if constexpr (Fused) {
      x[i] += dt * v1x;
      y[i] += dt * v1y;
      z[i] += dt * v1z;
      // The forces are spent: zero them for the coming contact loop while their lines are here
      // (a separate pass would stream them from memory once more).
      fx[i] = 0.0;
      fy[i] = 0.0;
      fz[i] = 0.0;
    }
  }
}

/// Spin half kick, w += h T / I, with the prediction as above; Fused: two of them, and the
/// torques zeroed as the forces are.
template <bool Predict, bool Fused>
void kick_spin(std::size_t n, double h, const double* __restrict I, double* __restrict tx,
               double* __restrict ty, double* __restrict tz, double* __restrict wx, double* __restrict wy,
               double* __restrict wz, double* __restrict px, double* __restrict py, double* __restrict pz) {
  for (std::size_t i = 0; i < n; ++i) {
    const double h_I = h / I[i];
    double w0x = wx[i], w0y = wy[i], w0z = wz[i];
    if constexpr (Fused) {
      w0x = w0x + h_I * tx[i];
      w0y = w0y + h_I * ty[i];
      w0z = w0z + h_I * tz[i];
    }
    const double w1x = w0x + h_I * tx[i], w1y = w0y + h_I * ty[i], w1z = w0z + h_I * tz[i];
    wx[i] = w1x;
    wy[i] = w1y;
    wz[i] = w1z;
    if constexpr (Predict) {
      px[i] = 2.0 * w1x - w0x;
      py[i] = 2.0 * w1y - w0y;
      pz[i] = 2.0 * w1z - w0z;
    }
    if constexpr (Fused) {
      tx[i] = 0.0;
      ty[i] = 0.0;
      tz[i] = 0.0;
    }
  }
}

/// Fused: also the displacement box of the drifted positions against ref (x, y, z), into box.
template <bool Predict, bool Track, bool Wet, bool Fused = false, bool Record = false>
void kick_all(std::size_t n, double h, double dt, const std::array<double, 3>& g, ParticleStore& s,
              std::vector<double>* pred, double* rz = nullptr, DisplacementBox* box = nullptr,
              const double* const* ref = nullptr) {
  double* p[6] = {nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
  if constexpr (Predict)
    for (int c = 0; c < 6; ++c) p[c] = pred[c].data();
  auto run = [&](std::size_t i0, std::size_t i1) {
    kick_loop<Predict, Track, Wet, Fused, Record>(
        i0, i1, h, dt, g[0], g[1], g[2], s.mass.data(), s.madd.data(), s.beta.data(), s.fx.data(),
        s.fy.data(), s.fz.data(), s.ext_x.data(), s.ext_y.data(), s.ext_z.data(), s.ufx.data(), s.ufy.data(),
        s.ufz.data(), s.vx.data(), s.vy.data(), s.vz.data(), s.drag_jx.data(), s.drag_jy.data(),
        s.drag_jz.data(), p[0], p[1], p[2], s.x.data(), s.y.data(), s.z.data(), rz);
  };
  if constexpr (Fused) {
    // The drifted positions' displacement box for the rebuild test, block by block while the
    // block's positions are in L1: the test then reads only the reference positions from memory
    // instead of those and the positions again.
    constexpr std::size_t kBlock = 512;
    for (std::size_t b = 0; b < n; b += kBlock) {
      const std::size_t e = std::min(n, b + kBlock);
      run(b, e);
      box->add(b, e, s.x.data(), s.y.data(), s.z.data(), ref[0], ref[1], ref[2]);
    }
  } else {
    run(0, n);
  }
  kick_spin<Predict, Fused>(n, h, s.inertia.data(), s.tx.data(), s.ty.data(), s.tz.data(), s.wx.data(),
                            s.wy.data(), s.wz.data(), p[3], p[4], p[5]);
}
/// a[0] + a[1] + ... in that order (the bits of a plain running sum).
double sum_in_order(const double* a, std::size_t n) {
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) sum += a[i];
  return sum;
}
}  // namespace

void DemSystem::kick(double h, bool predict) {
  // Half kick of velocity Verlet with the drag implicit (backward Euler over the half step):
  //   (M + h beta) v_new = M v + h (F + F_ext + m g + beta u_f),  M = m + m_add.
  // beta -> infinity gives v = u_f + F/beta: stable for any particle response time.
  // With `predict` (the step's first kick) it also writes the velocities the coming forces see
  // (see predict_velocities), 2 v(n+1/2) - v(n), while v(n) is at hand: one pass over the
  // arrays instead of a copy of v(n), the kick and a prediction pass (~8 % of a DEM step).
  const std::size_t n = s_.n_local;
  if (predict)
    for (int c = 0; c < 6; ++c) pred_[c].resize(s_.size());
  const bool track = cfg_.track_drag_impulse;
  // Dry only without drag tracking (tracking is for the coupling, which has fluid).
  const bool wet = !cfg_.dry || track;
  auto& g = cfg_.gravity_m_s2;
  if (predict && track)
    kick_all<true, true, true>(n, h, 0.0, g, s_, pred_);
  else if (track)
    kick_all<false, true, true>(n, h, 0.0, g, s_, pred_);
  else if (predict && wet)
    kick_all<true, false, true>(n, h, 0.0, g, s_, pred_);
  else if (wet)
    kick_all<false, false, true>(n, h, 0.0, g, s_, pred_);
  else if (predict)
    kick_all<true, false, false>(n, h, 0.0, g, s_, pred_);
  else
    kick_all<false, false, false>(n, h, 0.0, g, s_, pred_);
  if (predict) copy_ghost_predictions();
}

void DemSystem::copy_ghost_predictions() {
  // Ghost copies are not integrated here: they see the velocities their owner sent.
  const std::vector<double>* cur[6] = {&s_.vx, &s_.vy, &s_.vz, &s_.wx, &s_.wy, &s_.wz};
  for (int c = 0; c < 6; ++c)
    for (std::size_t i = s_.n_local; i < s_.size(); ++i) pred_[c][i] = (*cur[c])[i];
}

void DemSystem::kick_kick_drift(double h, double* vz_sum) {
  const std::size_t n = s_.n_local;
  for (int c = 0; c < 6; ++c) pred_[c].resize(s_.size());
  const bool track = cfg_.track_drag_impulse;
  const bool wet = !cfg_.dry || track;
  auto& g = cfg_.gravity_m_s2;
  const double dt = cfg_.dt_s;
  DisplacementBox box;
  const double* ref[3] = {verlet_.ref_x.data(), verlet_.ref_y.data(), verlet_.ref_z.data()};
  auto pass = [&](auto record, double* rz) {
    constexpr bool R = decltype(record)::value;
    if (track)
      kick_all<true, true, true, true, R>(n, h, dt, g, s_, pred_, rz, &box, ref);
    else if (wet)
      kick_all<true, false, true, true, R>(n, h, dt, g, s_, pred_, rz, &box, ref);
    else
      kick_all<true, false, false, true, R>(n, h, dt, g, s_, pred_, rz, &box, ref);
  };
  if (vz_sum) {
    // v_z at the end of the step exists only inside the pass: it is written out and summed after
    // (a sum inside the loop would keep it from vectorising).
    fused_.vz_end.resize(n);
    pass(std::true_type{}, fused_.vz_end.data());
    *vz_sum = sum_in_order(fused_.vz_end.data(), n);
  } else {
    pass(std::false_type{}, nullptr);
  }
  fused_.drift_box = box.result();
  fused_.drift_box_fresh = true;
  fused_.local_forces_zeroed = true;
  copy_ghost_predictions();
}

void DemSystem::drift() {
  const std::size_t n = s_.n_local;
  const double dt = cfg_.dt_s;
  for (int c = 0; c < 3; ++c) {
    double* __restrict x = (c == 0 ? s_.x : c == 1 ? s_.y : s_.z).data();
    const double* __restrict v = (c == 0 ? s_.vx : c == 1 ? s_.vy : s_.vz).data();
    for (std::size_t i = 0; i < n; ++i) x[i] += dt * v[i];
  }
}

void DemSystem::predict_velocities() {
  // Velocity Verlet evaluates forces at x(n+1) but only knows v(n+1/2); a dashpot fed with that
  // half-step-old velocity under-damps by O(gamma dt / m) (restitution 4 % low for e = 0.1 at
  // 100 steps per contact). The forces therefore see v(n+1) predicted to second order,
  // v(n+1/2) + (dt/2) a(n) = 2 v(n+1/2) - v(n), written by the step's first kick; at t = 0
  // (here) they see v(0).
  const std::vector<double>* cur[6] = {&s_.vx, &s_.vy, &s_.vz, &s_.wx, &s_.wy, &s_.wz};
  for (int c = 0; c < 6; ++c) pred_[c] = *cur[c];
}

void DemSystem::step() {
  advance(1);
}

void DemSystem::advance(int count, double* vz_sums) {
  advance_steps(count, vz_sums, 0, nullptr);
}

int DemSystem::advance_interruptible(int count, int check_every, const std::function<bool()>& stop) {
  return advance_steps(count, nullptr, std::max(check_every, 1), &stop);
}

int DemSystem::advance_steps(int count, double* vz_sums, int check_every, const std::function<bool()>* stop) {
  if (!initialized_) initialize();
  for (int k = 0; k < count; ++k) {
    auto t0 = std::chrono::steady_clock::now();
    if (k == 0) {
      kick(0.5 * cfg_.dt_s, true);
      drift();
    } else {
      // the closing kick in this pass ends step k - 1
      kick_kick_drift(0.5 * cfg_.dt_s, vz_sums ? vz_sums + (k - 1) : nullptr);
    }
    seconds_integrate += seconds_since(t0);
    advance_to_forces();
    // The stop is asked between steps without closing them: the fused passes run on across the
    // asks, so a step asked every 2 sub-steps (a 405 000-particle case) costs what an unasked one
    // does (separate closing and opening kicks there took 2.6 % of the run, perf).
    const bool last = k == count - 1 || (stop && (k + 1) % check_every == 0 && (*stop)());
    if (last) {
      t0 = std::chrono::steady_clock::now();
      kick(0.5 * cfg_.dt_s, false);
      if (vz_sums) vz_sums[k] = sum_in_order(s_.vz.data(), s_.n_local);
      seconds_integrate += seconds_since(t0);
    }
    counters_.time_s += cfg_.dt_s;
    ++counters_.steps;
    if (last) return k + 1;
  }
  return count;
}

void DemSystem::advance_to_forces() {
  std::chrono::steady_clock::time_point t0;
  const bool rebuild_now = dd_.parallel() ? needs_rebuild_parallel() : needs_rebuild();
  fused_.drift_box_fresh = false;  // read by the test just made; a rebuild moves the references
  if (dd_.parallel()) {
    if (rebuild_now) {
      rebuild_parallel();
    } else {
      t0 = std::chrono::steady_clock::now();
      forward_ghosts();
      seconds_ghosts += seconds_since(t0);
    }
  } else if (rebuild_now) {
    rebuild();
  }
  compute_forces();
}

}  // namespace boycott::particles
