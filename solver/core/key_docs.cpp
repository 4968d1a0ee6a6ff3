#include "core/key_docs.hpp"

#include <algorithm>
#include <array>
#include <vector>

namespace boycott {

namespace {
constexpr std::array kDocs = {
    KeyDoc{"scene", "", "what is simulated and measured (see the scene table of the README)"},
    KeyDoc{"seed", "-", "random seed of particle insertion and of the initial perturbations"},
    KeyDoc{"fluid.density", "kg/m^3", "fluid density rho_f"},
    KeyDoc{"fluid.viscosity", "Pa s", "dynamic viscosity mu_f"},
    KeyDoc{"fluid.subgrid_model", "", "LES subgrid model: vreman (the paper's) or none"},
    KeyDoc{"particles.diameter", "m", "particle diameter d"},
    KeyDoc{"particles.density", "kg/m^3", "particle density rho_p"},
    KeyDoc{"particles.count", "-", "number of particles (or give volume_fraction)"},
    KeyDoc{"particles.volume_fraction", "-", "solid fraction alpha_p of the box; overrides count"},
    KeyDoc{"particles.insertion", "", "random: uniform in the box; bed: packed from y = 0 before the run"},
    KeyDoc{"contact.stiffness", "N/m", "normal and tangential spring stiffness k_n = k_t"},
    KeyDoc{"contact.restitution", "-", "coefficient of restitution e (sets the normal damping)"},
    KeyDoc{"contact.friction", "-", "sliding friction coefficient mu_s (Coulomb cap, Eq. 10)"},
    KeyDoc{"contact.rolling_friction", "-", "rolling friction coefficient mu_r (Eq. 11)"},
    KeyDoc{"contact.tangential_damping_ratio", "-", "gamma_t / gamma_n"},
    KeyDoc{"contact.model", "", "contact force law (linear_spring_dashpot)"},
    KeyDoc{"contact.rolling_model", "", "rolling resistance: constant_directional or none"},
    KeyDoc{"contact.clip_attractive_normal", "", "true: the normal force never turns attractive"},
    KeyDoc{"domain.length_x", "m", "box length along x (periodic, along the channel)"},
    KeyDoc{"domain.width_y", "m", "gap between the walls at y = 0 and y = W"},
    KeyDoc{"domain.height_z", "m", "box height along z (periodic, settling direction)"},
    KeyDoc{"domain.cells", "-", "fluid cells [nx, ny, nz]"},
    KeyDoc{"domain.periodic_y", "", "true: periodic in y instead of walls"},
    KeyDoc{"domain.top_wall", "", "fluid condition at y = W: no_slip or slip"},
    KeyDoc{"gravity.angle_deg", "deg", "inclination theta from the horizontal; 90 is vertical"},
    KeyDoc{"gravity.magnitude", "m/s^2", "magnitude of the gravitational acceleration"},
    KeyDoc{"time.dt_cfd", "s", "fluid time step (upper bound; the CFL limit may lower it)"},
    KeyDoc{"time.dt_dem", "s", "particle time step"},
    KeyDoc{"time.end", "s", "simulated time at which the run ends (raise it to continue a run)"},
    KeyDoc{"time.average_from", "s",
           "start of the averaging window of <<w_p>>, or \"auto\": where its start-up transient ends"},
    KeyDoc{"time.checkpoint_every", "s", "simulated time between restart checkpoints"},
    KeyDoc{"time.target_rel_error", "-", "stop once the relative error of <<w_p>> is below this"},
    KeyDoc{"forces.drag", "", "drag law (difelice_paper, difelice, schiller_naumann, stokes, none)"},
    KeyDoc{"forces.saffman_lift", "", "shear lift on or off (off: forces.lift = none)"},
    KeyDoc{"forces.lift", "",
           "shear lift law: saffman (Eq. 16), saffman_mei (Mei 1992 finite-Re factor), none"},
    KeyDoc{"forces.added_mass", "", "added-mass force on or off"},
    KeyDoc{"forces.pressure_gradient", "", "pressure-gradient force on or off"},
    KeyDoc{"forces.viscous", "", "viscous-stress (divergence of tau) force on or off"},
    KeyDoc{"flow.body_acceleration", "m/s^2", "body acceleration [x, y, z] driving the fluid"},
    KeyDoc{"flow.target_mean_velocity_z", "m/s", "mean z-velocity held by a flux controller (unset: off)"},
    KeyDoc{"numerics.simple_max_iterations", "-", "SIMPLE iterations per fluid step at most"},
    KeyDoc{"numerics.simple_tolerance", "-", "relative change of the continuity residual ending SIMPLE"},
    KeyDoc{"numerics.velocity_relaxation", "-", "under-relaxation of velocity (SIMPLE only)"},
    KeyDoc{"numerics.pressure_relaxation", "-",
           "takes only its default: SIMPLEC applies the pressure correction whole"},
    KeyDoc{"numerics.pressure_velocity_coupling", "", "simple (the paper's) or piso"},
    KeyDoc{"numerics.piso_correctors", "-", "pressure corrections per PISO step"},
    KeyDoc{"numerics.simple_correctors", "-", "pressure corrections per SIMPLE iteration"},
    KeyDoc{"numerics.cfl_max", "-", "largest Courant number; lowers dt_cfd when exceeded"},
    KeyDoc{"numerics.neighbor_skin", "m", "Verlet skin of the contact neighbour lists"},
    KeyDoc{"numerics.void_fraction_kernel", "", "deposition kernel of particle volume and forces"},
    KeyDoc{"numerics.sampling", "", "fluid read at particles: kernel or trilinear (wall rules)"},
    KeyDoc{"numerics.vorticity", "",
           "vorticity for the lift: cell_centres (2-cell central) or edges (compact)"},
    KeyDoc{"output.timeseries_every", "s",
           "simulated time between rows of timeseries.csv (unset: every step)"},
    KeyDoc{"output.keep_checkpoints", "-", "newest checkpoints kept"},
    KeyDoc{"output.snapshot_times", "s", "times of XDMF/HDF5 snapshots of particles and fluid"},
    KeyDoc{"output.image_times", "s", "times of PNG images of the particles"},
    KeyDoc{"output.pdf_bins", "-", "bins of the PDFs of y and w_p"},
    KeyDoc{"output.force_budget_y", "",
           "write force_budget_y.csv: each force on the particles per band of y"},
    KeyDoc{"ergun.pressure_gradients", "Pa/m", "driving pressure gradients swept over the frozen bed"},
    KeyDoc{"sediment.bulk_velocity", "m/s", "target z-averaged bulk velocity of the flow over the bed"},
    KeyDoc{"sediment.bed_height", "m", "bed height (unset: from the particle count)"},
    KeyDoc{"sediment.initial_flow", "", "fluid at t = 0: turbulent (log law, perturbed) or rest"},
};
}  // namespace

namespace {
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

std::string_view last_part(std::string_view key) {
  const auto dot = key.rfind('.');
  return dot == std::string_view::npos ? key : key.substr(dot + 1);
}
}  // namespace

std::string did_you_mean(std::string_view key) {
  std::string_view best;
  std::size_t best_d = std::max<std::size_t>(2, key.size() / 5) + 1;
  for (const auto& d : kDocs) {
    // The right name in the wrong section ("time.viscosity") counts as one edit.
    const std::size_t dist = last_part(d.key) == last_part(key) ? 1 : edit_distance(key, d.key);
    if (dist < best_d) best_d = dist, best = d.key;
  }
  return best.empty() ? "" : " (did you mean '" + std::string(best) + "'?)";
}

std::optional<KeyDoc> key_doc(std::string_view key) {
  for (const auto& d : kDocs)
    if (d.key == key) return d;
  return std::nullopt;
}

}  // namespace boycott
