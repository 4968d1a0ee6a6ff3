#include "checks/preflight.hpp"

#include <unistd.h>

#include <cstdlib>
#include <fstream>

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/constants.hpp"
#include "core/error.hpp"
#include "core/scene_specs.hpp"
#include "coupling/drag_laws.hpp"
#include "coupling/drag_stability.hpp"

namespace boycott::checks {

namespace {

// Largest weight a kernel gives one cell, for a particle centred in it (1-D weight cubed).
// cell and trilinear put everything in one cell; the smoothed (TSC) kernel 0.75 per direction.
double kernel_peak_weight(const std::string& kernel) {
  if (kernel == "trilinear_smoothed") return 0.75 * 0.75 * 0.75;
  return 1.0;
}

}  // namespace

double collision_time_s(double mass_kg, double stiffness_n_m, double restitution) {
  const double m_eff = 0.5 * mass_kg;
  const double w0 = std::sqrt(stiffness_n_m / m_eff);
  const double le = std::log(std::max(restitution, 1e-300));
  const double zeta = -le / std::sqrt(kPi * kPi + le * le);
  return kPi / (w0 * std::sqrt(std::max(1.0 - zeta * zeta, 1e-300)));
}

namespace {
double read_machine_memory_bytes() {
  double bytes = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
  // A container's limit (cgroup v2), where there is one.
  std::ifstream in("/sys/fs/cgroup/memory.max");
  std::string limit;
  if (in >> limit && limit != "max") {
    char* end = nullptr;
    const double v = std::strtod(limit.c_str(), &end);
    if (end != limit.c_str() && v > 0.0) bytes = std::min(bytes, v);
  }
  return bytes;
}
}  // namespace

double machine_memory_bytes() {
  // Read once: a study checks every case, and the machine does not change under it.
  static const double bytes = read_machine_memory_bytes();
  return bytes;
}

double memory_estimate_bytes(const CaseParams& p, int ranks) {
  // Per particle: ~40 arrays of the store, predicted velocities and reference positions (~0.4
  // kB), and ~20 list pairs of ~110 B (indices and flags; the contacts' springs and force arrays).
  // Per cell: ~110 fluid and coupling arrays and ~60 Krylov work vectors of 8 B. Rank 0 also
  // holds the gathered checkpoint twice while writing it (~0.45 kB per particle, ~0.2 per cell).
  constexpr double kPerParticle = 2600.0, kPerCell = 1400.0, kCheckpointParticle = 900.0,
                   kCheckpointCell = 200.0;
  const double cells = static_cast<double>(p.domain.cells[0] * p.domain.cells[1] * p.domain.cells[2]);
  const double particles = static_cast<double>(p.particles.count);
  const bool fluid = scene_spec(p.scene).has_fluid;
  const double n = std::max(ranks, 1);
  return kPerParticle * particles / n + (fluid ? kPerCell * cells / n : 0.0) +
         kCheckpointParticle * particles + (fluid ? kCheckpointCell * cells : 0.0) +
         64.0e6;  // + the program itself
}

namespace {

void add_item(Preflight& r, std::string name, double v, std::string unit, std::string meaning) {
  r.items.push_back({std::move(name), v, std::move(unit), std::move(meaning)});
}

void check_memory(const CaseParams& p, int ranks, Preflight& r) {
  const double mem = memory_estimate_bytes(p, ranks), have = machine_memory_bytes();
  add_item(r, "memory_estimate_per_rank", mem, "B",
           fmt::format("peak memory of one of {} rank(s), estimated", ranks));
  if (mem > have)
    r.machine_errors.push_back(
        fmt::format("the case needs about {:.3g} GB per rank on {} rank(s), more than this "
                    "machine's {:.3g} GB: use more ranks (on more machines) or a smaller "
                    "domain.cells or particles.count",
                    mem / 1e9, ranks, have / 1e9));
}

/// One particle alone must not fill a cell: its kernel-weighted volume over the cell volume.
void check_kernel_resolution(const CaseParams& p, Preflight& r) {
  const double dx[3] = {p.domain.length_x_m / p.domain.cells[0], p.domain.width_y_m / p.domain.cells[1],
                        p.domain.height_z_m / p.domain.cells[2]};
  const double cell_v = dx[0] * dx[1] * dx[2];
  const double peak = kernel_peak_weight(p.numerics.void_fraction_kernel) * p.particle_volume_m3() / cell_v;
  add_item(r, "single_particle_peak_solid_fraction", peak, "",
           "largest share of one cell that one particle fills");
  if (peak >= 1.0)
    r.errors.push_back(fmt::format(
        "one particle fills {:.2f} of a cell (particles.diameter = {} m, cells {:.3g} x {:.3g} x {:.3g} m, "
        "kernel "
        "{}): the fluid fraction would go negative; must be < 1: use coarser domain.cells or the "
        "trilinear_smoothed kernel",
        peak, p.particles.diameter_m, dx[0], dx[1], dx[2], p.numerics.void_fraction_kernel));
  else if (peak > 0.5)
    r.warnings.push_back(fmt::format(
        "one particle fills {:.2f} of a cell: the unresolved (volume-averaged) description is doubtful",
        peak));
}

/// The lift law against the settling Reynolds number Re_p (the isolated terminal slip's) of
/// the published range it rests on (coupling/lift_laws.hpp). Each law also needs a shear
/// Reynolds number Re_w = |w| d^2 / nu, a property of the flow that is not known before the run
/// (output.force_budget_y reports it per band), so only Re_p is judged here, and the message
/// names the Re_w condition too.
void check_lift_range(const CaseParams& p, double re_p, Preflight& r) {
  const std::string law = p.forces.saffman_lift ? p.forces.lift : "none";
  const std::string instead =
      re_p <= 100.0 ? "; saffman_mei is fitted up to Re_p = 100" : "; no lift law here covers Re_p > 100";
  // The asymptotic theories assume Re_p << 1; from Re_p = 1 a case is outside them.
  if (law == "saffman" && re_p >= 1.0)
    r.warnings.push_back(fmt::format(
        "forces.lift = \"saffman\" at Re_p = {:.3g}: Saffman's (1965, 1968) lift holds for Re_p << "
        "Re_w^1/2 << 1 (slip and shear Reynolds numbers both small, the shear's dominating){}",
        re_p, instead));
  if (law == "mclaughlin" && re_p >= 1.0)
    r.warnings.push_back(fmt::format(
        "forces.lift = \"mclaughlin\" at Re_p = {:.3g}: McLaughlin's (1991) J(epsilon) holds for Re_p << 1 "
        "and Re_w << 1 (epsilon = Re_w^1/2 / Re_p free){}",
        re_p, instead));
  // Mei (1992) fitted Dandy & Dwyer's (1990) computations over 0.1 <= Re_p <= 100 and
  // 0.005 <= Re_w / (2 Re_p) <= 0.4.
  if ((law == "saffman_mei" || law == "saffman_mei_continuous") && (re_p < 0.1 || re_p > 100.0))
    r.warnings.push_back(fmt::format(
        "forces.lift = \"{}\" at Re_p = {:.3g}: Mei's (1992) factor is a fit over 0.1 "
        "<= Re_p <= 100 "
        "and 0.005 <= Re_w / (2 Re_p) <= 0.4 (Dandy & Dwyer's 1990 computations){}",
        law, re_p, re_p < 0.1 ? "; below it mclaughlin (Re_p << 1, Re_w << 1) is the theory" : ""));
}

/// The settling scales from the case's own drag law, and the steps and cells measured against
/// them. Returns the isolated terminal speed w_t, m/s.
double check_settling_scales(const CaseParams& p, Preflight& r) {
  const double d = p.particles.diameter_m, rho_p = p.particles.density_kg_m3, rho_f = p.fluid.density_kg_m3;
  const double mu = p.fluid.viscosity_pa_s, nu = mu / rho_f, g = p.gravity.magnitude_m_s2;
  const double dx_min =
      std::min({p.domain.length_x_m / p.domain.cells[0], p.domain.width_y_m / p.domain.cells[1],
                p.domain.height_z_m / p.domain.cells[2]});
  const double m = p.particle_mass_kg();
  const double wt = coupling::visit_drag_law(p.forces.drag, [&](const auto& law) {
    return coupling::terminal_slip_speed(law, 1.0, d, rho_p, rho_f, mu, g);
  });
  const double re = rho_f * wt * d / mu;
  add_item(r, "terminal_velocity", wt, "m/s",
           fmt::format("isolated terminal speed, drag law {}", p.forces.drag));
  add_item(r, "Re_p", re, "", "particle Reynolds number rho_f w_t d / mu");
  if (scene_reads(scene_spec(p.scene), "forces.lift")) check_lift_range(p, re, r);
  add_item(r, "St", rho_p / rho_f * re / 9.0, "", "collision Stokes number (rho_p/rho_f) Re_p / 9");
  // Response time: how long the particle takes to reach w_t (weight against drag, added mass
  // included), the time scale a time step has to be compared with.
  const double m_f = rho_f * p.particle_volume_m3();
  const double m_virtual = m + (p.forces.added_mass ? 0.5 * m_f : 0.0);
  const double tau = std::abs(m - m_f) > 0.0 && wt > 0.0
                         ? m_virtual * wt / (std::abs(m - m_f) * g)
                         : m_virtual / (3.0 * kPi * mu * d);  // Stokes when neutrally buoyant
  add_item(r, "response_time", tau, "s", "particle response time (m + m_added) w_t / ((m - m_f) g)");
  add_item(r, "dt_dem_over_response_time", p.time.dt_dem_s / tau, "",
           "drag is implicit per DEM step: > 1 is stable");
  if (p.time.dt_dem_s > tau)
    r.warnings.push_back(
        fmt::format("time.dt_dem = {:.3g} s exceeds the particle response time {:.3g} s: the implicit drag "
                    "keeps it stable, "
                    "but transients shorter than a DEM step are not resolved",
                    p.time.dt_dem_s, tau));
  if (p.time.dt_cfd_s > 10.0 * tau)
    r.warnings.push_back(
        fmt::format("time.dt_cfd = {:.3g} s is {:.0f} response times: the fluid sees the drag of particles "
                    "that relaxed "
                    "within the step (coupling lag); consider a smaller time.dt_cfd",
                    p.time.dt_cfd_s, p.time.dt_cfd_s / tau));
  const double ratio = dx_min / d;
  add_item(r, "dx_over_d", ratio, "", "smallest cell over particle diameter");
  // The particle's own disturbance in the sampled velocity (measured at Re_p 1.6: +3.3 % in
  // w_t at dx/d = 3, +7.1 % at 2; below 1 % at Re_p >= 50 for dx/d = 5).
  if (re < 10.0 && ratio < 3.0)
    r.warnings.push_back(fmt::format(
        "smallest cell / particles.diameter = {:.2f} < 3 at Re_p = {:.3g}: the particle's own disturbance "
        "in "
        "the sampled fluid velocity biases its drag by several percent (no correction is applied)",
        ratio, re));
  // Expected CFL at three terminal speeds (convection in the channel reaches about twice w_t).
  const double cfl = 3.0 * wt * p.time.dt_cfd_s / dx_min;
  add_item(r, "expected_cfl", cfl, "", "3 w_t dt_cfd / dx_min");
  if (cfl > p.numerics.cfl_max)
    r.warnings.push_back(
        fmt::format("expected CFL 3 w_t dt_cfd / dx = {:.2f} exceeds numerics.cfl_max = {}: "
                    "the CFD step will be cut below time.dt_cfd",
                    cfl, p.numerics.cfl_max));
  add_item(r, "cell_reynolds", 3.0 * wt * dx_min / nu, "", "3 w_t dx_min / nu");
  return wt;
}

/// The exchange of a packed bed (slip -> 0): the step its particles allow against time.dt_cfd.
void check_packed_exchange(const CaseParams& p, Preflight& r) {
  const double bound = packed_bed_stable_dt_s(p);
  add_item(r, "packed_bed_stable_dt", bound, "s",
           "largest dt_cfd of a stable exchange in a packed bed (alpha_f 0.36)");
  if (bound >= p.time.dt_cfd_s) return;
  if (p.numerics.drag_dt_limit)
    r.warnings.push_back(fmt::format(
        "where the particles pack (alpha_f ~0.36) the CFD step is cut from time.dt_cfd = {:.3g} s to "
        "about {:.3g} s (numerics.drag_dt_limit): up to {:.1f}x the fluid's cost there",
        p.time.dt_cfd_s, bound, p.time.dt_cfd_s / bound));
  else
    r.warnings.push_back(fmt::format(
        "numerics.drag_dt_limit = false and time.dt_cfd = {:.3g} s exceeds the {:.3g} s a packed bed's "
        "particle-fluid exchange is stable at: a bed that forms will oscillate step by step until the "
        "run stops with alpha_f outside (0, 1]",
        p.time.dt_cfd_s, bound));
}

/// Contacts: resolution of a binary collision and the overlap at the impact speed (the terminal
/// speed `wt` in a fluid, a fall across the channel width when dry).
void check_contacts(const CaseParams& p, double wt, Preflight& r) {
  const double m = p.particle_mass_kg(), d = p.particles.diameter_m;
  const double tc = collision_time_s(m, p.contact.stiffness_n_m, p.contact.restitution);
  add_item(r, "collision_time", tc, "s", "binary collision time of the spring-dashpot");
  add_item(r, "steps_per_collision", tc / p.time.dt_dem_s, "", "collision time / dt_dem");
  add_item(r, "dt_dem_over_spring_limit", p.time.dt_dem_s / p.dem_spring_limit_s(), "",
           "must be <= 1: (pi/5) sqrt(m/k)");
  if (tc / p.time.dt_dem_s < 20.0)
    r.warnings.push_back(
        fmt::format("a collision takes {:.1f} DEM steps (< 20): the rebound restitution is off by a few "
                    "percent (measured "
                    "+3.6 % for e = 0.1 at 40 steps)",
                    tc / p.time.dt_dem_s));
  const double v_imp = wt > 0.0 ? wt : std::sqrt(2.0 * p.gravity.magnitude_m_s2 * p.domain.width_y_m);
  const double overlap = v_imp * std::sqrt(0.5 * m / p.contact.stiffness_n_m) / d;
  add_item(r, "impact_overlap_over_d", overlap, "",
           "undamped overlap of a head-on impact at the impact speed / d");
  if (overlap > 0.5)
    r.errors.push_back(
        fmt::format("contact.stiffness = {} N/m is too soft: an impact at {:.3g} m/s overlaps {:.2f} d "
                    "(must be <= 0.5 d, or spheres pass through each other)",
                    p.contact.stiffness_n_m, v_imp, overlap));
  else if (overlap > 0.1)
    r.warnings.push_back(
        fmt::format("an impact at {:.3g} m/s overlaps {:.2f} d (> 0.1 d): soft contacts compress "
                    "the packing",
                    v_imp, overlap));
}

/// Values that are valid but most often a slip of the pen.
void check_likely_slips(const CaseParams& p, bool fluid, Preflight& r) {
  // An inclination in radians written where degrees are read (1.2 meant as 69 degrees).
  const double th = p.gravity.angle_deg;
  if (scene_reads(scene_spec(p.scene), "gravity.angle_deg") && th > 0.0 && th < 2.0 && th != std::floor(th))
    r.warnings.push_back(fmt::format(
        "gravity.angle_deg = {:g}: an inclination in degrees below 2 that is not a whole number; if it "
        "was meant in radians it is {:.4g} degrees",
        th, th * 180.0 / kPi));
  const double sg = p.particles.density_kg_m3 / p.fluid.density_kg_m3;
  if (fluid && sg < 1.1)
    r.warnings.push_back(
        fmt::format("nearly neutrally buoyant particles (rho_p/rho_f = {:.3g}): settling is slow "
                    "and the averaging window should be long",
                    sg));
}

}  // namespace

double packed_bed_stable_dt_s(const CaseParams& p) {
  const SceneSpec& sc = scene_spec(p.scene);
  if (!sc.has_fluid || !sc.particles_move || p.forces.drag == "none" || p.particles.count < 1)
    return std::numeric_limits<double>::infinity();
  constexpr double kPackedAlphaF = 0.36;
  const double d = p.particles.diameter_m, rho_f = p.fluid.density_kg_m3, mu = p.fluid.viscosity_pa_s;
  const double beta = coupling::visit_drag_law(
      p.forces.drag, [&](const auto& law) { return law.beta(kPackedAlphaF, 0.0, d, rho_f, mu); });
  const double m_added = p.forces.added_mass ? 0.5 * rho_f * p.particle_volume_m3() : 0.0;
  return coupling::drag_stable_dt_s(kPackedAlphaF, (p.particle_mass_kg() + m_added) / beta);
}

Preflight preflight(const CaseParams& p, int ranks) {
  Preflight r;
  const SceneSpec& sc = scene_spec(p.scene);
  const bool fluid = sc.has_fluid;
  check_memory(p, ranks, r);
  if (fluid) {
    const double W = p.domain.width_y_m, nu = p.fluid.viscosity_pa_s / p.fluid.density_kg_m3;
    add_item(r, "Ga", std::sqrt(p.gravity.magnitude_m_s2 * W * W * W) / nu, "",
             "Galileo number sqrt(g W^3)/nu (Eq. 26)");
  }
  if (sc.own_checks) {
    SceneFindings own;
    sc.own_checks(p, own);
    r.errors.insert(r.errors.end(), own.errors.begin(), own.errors.end());
    r.warnings.insert(r.warnings.end(), own.warnings.begin(), own.warnings.end());
  }
  if (p.particles.count < 1) return r;
  add_item(r, "Sg", p.particles.density_kg_m3 / p.fluid.density_kg_m3, "",
           "density ratio rho_p/rho_f (Eq. 26)");
  add_item(r, "Sr", p.particles.diameter_m / p.domain.width_y_m, "", "size ratio d/W (Eq. 26)");
  add_item(r, "solid_fraction", p.solid_fraction(), "", "alpha_p of the whole box");
  if (fluid) check_kernel_resolution(p, r);
  if (!sc.particles_move) return r;
  const double wt = fluid && p.forces.drag != "none" ? check_settling_scales(p, r) : 0.0;
  if (fluid && p.forces.drag != "none") check_packed_exchange(p, r);
  check_contacts(p, wt, r);
  check_likely_slips(p, fluid, r);
  return r;
}

nlohmann::json Preflight::to_json() const {
  nlohmann::json j;
  for (const auto& it : items)
    j["items"][it.name] = {{"value", it.value}, {"unit", it.unit}, {"meaning", it.meaning}};
  j["warnings"] = warnings;
  j["errors"] = errors;
  j["machine_errors"] = machine_errors;
  return j;
}

std::string Preflight::text() const {
  std::string s;
  for (const auto& it : items)
    s += fmt::format("  {:<36} {:>12.4g} {:<4} {}\n", it.name, it.value, it.unit, it.meaning);
  for (const auto& w : warnings) s += "  warning: " + w + "\n";
  for (const auto& e : errors) s += "  error: " + e + "\n";
  for (const auto& e : machine_errors) s += "  on this machine: " + e + "\n";
  return s;
}

}  // namespace boycott::checks
