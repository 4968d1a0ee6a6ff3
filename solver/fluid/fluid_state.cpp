// FluidSolver's state: fields set by hand (initial conditions, tests), diagnostics over the
// whole grid, and the checkpoint state.
#include "fluid/fluid_solver.hpp"

#include <algorithm>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "fluid/halo_exchange.hpp"
#include "fluid/petsc_check.hpp"

namespace boycott::fluid {

void FluidSolver::set_velocity(int c, const std::function<double(double, double, double)>& f) {
  const auto& g = s_.grid;
  const OwnedBox b = owned_box();
  PetscScalar*** u;
  BC_PETSC(DMDAVecGetArray(layout_.da, flow_.U[c], &u));
  for (auto k = b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (auto j = b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (auto i = b.lo[0]; i < b.lo[0] + b.size[0]; ++i) {
        double x[3] = {(i + 0.5) * g.dx(0), (j + 0.5) * g.dx(1), (k + 0.5) * g.dx(2)};
        const std::int64_t idx[3] = {i, j, k};
        x[c] = idx[c] * g.dx(c);
        const bool wall = c == 1 && !g.periodic[1] && j == 0;
        u[k][j][i] = wall ? 0.0 : f(x[0], x[1], x[2]);
      }
  BC_PETSC(DMDAVecRestoreArray(layout_.da, flow_.U[c], &u));
  BC_PETSC(VecCopy(flow_.U[c], flow_.Un[c]));
  BC_PETSC(VecCopy(flow_.U[c], flow_.Unm1[c]));
  layout_.halo->fill(flow_.U[c], ghosts_.U[c]);
}

void FluidSolver::set_fluid_fraction(const std::function<double(double, double, double)>& f) {
  const auto& g = s_.grid;
  const OwnedBox b = owned_box();
  PetscScalar*** a;
  double amin = 1.0, amax = 0.0;
  BC_PETSC(DMDAVecGetArray(layout_.da, flow_.alpha[0], &a));
  for (auto k = b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (auto j = b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (auto i = b.lo[0]; i < b.lo[0] + b.size[0]; ++i) {
        const double v = f((i + 0.5) * g.dx(0), (j + 0.5) * g.dx(1), (k + 0.5) * g.dx(2));
        a[k][j][i] = v;
        amin = std::min(amin, v), amax = std::max(amax, v);
      }
  BC_PETSC(DMDAVecRestoreArray(layout_.da, flow_.alpha[0], &a));
  if (!(amin > 0.0) || !(amax <= 1.0))
    throw PhysicsError(fmt::format("fluid fraction outside (0, 1]: min {:.4g}, max {:.4g}", amin, amax));
  if (!flow_.alpha_initialised && flow_.steps == 0) {
    BC_PETSC(VecCopy(flow_.alpha[0], flow_.alpha[1]));
    BC_PETSC(VecCopy(flow_.alpha[0], flow_.alpha[2]));
  }
  flow_.alpha_initialised = true;
  for (int l = 0; l < 3; ++l) layout_.halo->fill(flow_.alpha[l], ghosts_.alpha[l]);
}

// ---------------------------------------------------------------- diagnostics

double FluidSolver::mean_velocity(int c) const {
  PetscScalar sum;
  VecSum(flow_.U[c], &sum);
  return sum / static_cast<double>(s_.grid.cell_count());
}

double FluidSolver::max_abs_velocity(int c) const {
  PetscReal m;
  VecNorm(flow_.U[c], NORM_INFINITY, &m);
  return m;
}

double FluidSolver::max_continuity_defect() const {
  return counters_.last_defect;
}

std::vector<double> FluidSolver::profile_y(int c) const {
  const OwnedBox b = owned_box();
  const int ny = (int)s_.grid.n[1];
  std::vector<double> loc(ny, 0.0), glob(ny, 0.0);
  PetscScalar*** u;
  DMDAVecGetArray(layout_.da, flow_.U[c], &u);
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i) loc[j] += u[k][j][i];
  DMDAVecRestoreArray(layout_.da, flow_.U[c], &u);
  MPI_Allreduce(loc.data(), glob.data(), ny, MPI_DOUBLE, MPI_SUM, comm_);
  const double nxz = static_cast<double>(s_.grid.n[0] * s_.grid.n[2]);
  for (auto& v : glob) v /= nxz;
  return glob;
}

std::vector<double> FluidSolver::gather(int c) const {
  Vec src = c < 3 ? flow_.U[c] : (c == 3 ? flow_.P : (c == 4 ? flow_.nut : flow_.alpha[1]));
  Vec nat, all;
  VecScatter sc;
  BC_PETSC(DMDACreateNaturalVector(layout_.da, &nat));
  BC_PETSC(DMDAGlobalToNaturalBegin(layout_.da, src, INSERT_VALUES, nat));
  BC_PETSC(DMDAGlobalToNaturalEnd(layout_.da, src, INSERT_VALUES, nat));
  BC_PETSC(VecScatterCreateToAll(nat, &sc, &all));
  BC_PETSC(VecScatterBegin(sc, nat, all, INSERT_VALUES, SCATTER_FORWARD));
  BC_PETSC(VecScatterEnd(sc, nat, all, INSERT_VALUES, SCATTER_FORWARD));
  PetscInt nloc;
  BC_PETSC(VecGetLocalSize(all, &nloc));
  const PetscScalar* a;
  BC_PETSC(VecGetArrayRead(all, &a));
  std::vector<double> out(a, a + nloc);
  BC_PETSC(VecRestoreArrayRead(all, &a));
  VecScatterDestroy(&sc);
  VecDestroy(&all);
  VecDestroy(&nat);
  return out;
}

// ---------------------------------------------------------------- checkpoints

FluidState FluidSolver::export_state() const {
  FluidState st;
  st.box = owned_box();
  st.time_s = flow_.time_s;
  st.dt_prev_s = flow_.dt_prev_s;
  st.steps = flow_.steps;
  st.mean_pressure_gradient_pa_m = flow_.G_pa_m;
  // nu_t too: it was computed from the previous level at the start of the last step, and the
  // coupling reads it before the next step recomputes it.
  const Vec vs[11] = {flow_.U[0],     flow_.U[1],     flow_.U[2], flow_.Unm1[0],
                      flow_.Unm1[1],  flow_.Unm1[2],  flow_.P,    flow_.alpha[1],
                      flow_.alpha[2], flow_.alpha[0], flow_.nut};
  for (Vec v : vs) {
    PetscInt nloc;
    VecGetLocalSize(v, &nloc);
    const PetscScalar* a;
    VecGetArrayRead(v, &a);
    st.fields.emplace_back(a, a + nloc);
    VecRestoreArrayRead(v, &a);
  }
  return st;
}

void FluidSolver::import_state(const FluidState& st) {
  const OwnedBox b = owned_box();
  if (st.box.lo != b.lo || st.box.size != b.size || st.fields.size() != 11)
    throw std::invalid_argument("fluid state from another layout");
  Vec vs[11] = {flow_.U[0], flow_.U[1],     flow_.U[2],     flow_.Unm1[0],  flow_.Unm1[1], flow_.Unm1[2],
                flow_.P,    flow_.alpha[1], flow_.alpha[2], flow_.alpha[0], flow_.nut};
  for (int f = 0; f < 11; ++f) {
    PetscScalar* a;
    BC_PETSC(VecGetArray(vs[f], &a));
    std::copy(st.fields[f].begin(), st.fields[f].end(), a);
    BC_PETSC(VecRestoreArray(vs[f], &a));
  }
  for (int c = 0; c < 3; ++c) BC_PETSC(VecCopy(flow_.U[c], flow_.Un[c]));
  flow_.time_s = st.time_s;
  flow_.dt_prev_s = st.dt_prev_s;
  flow_.steps = st.steps;
  flow_.G_pa_m = st.mean_pressure_gradient_pa_m;
  flow_.alpha_initialised = true;
  for (int l = 0; l < 3; ++l) layout_.halo->fill(flow_.alpha[l], ghosts_.alpha[l]);
  layout_.halo->fill(flow_.nut, ghosts_.nut);
  update_ghosts();
}

}  // namespace boycott::fluid
