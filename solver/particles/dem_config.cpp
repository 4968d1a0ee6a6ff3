// The particle engine's configuration from a case: the box, walls, step and contact model,
// the checks of the model names, and the models a case switches on (for the run's timers).
#include "particles/dem_config.hpp"

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/timers.hpp"

namespace boycott::particles {

bool rolling_model_enabled(const std::string& name) {
  if (name == "constant_directional") return true;
  if (name == "none") return false;
  throw InputError(fmt::format("contact.rolling_model = \"{}\" is not a rolling model of this engine", name));
}

void check_contact_model(const std::string& name) {
  if (name != "linear_spring_dashpot")
    throw InputError(fmt::format("contact.model = \"{}\" is not a contact model of this engine", name));
}

DemConfig DemConfig::from_case(const CaseParams& p) {
  DemConfig c;
  c.box.lo = {0.0, 0.0, 0.0};
  c.box.len = {p.domain.length_x_m, p.domain.width_y_m, p.domain.height_z_m};
  c.box.periodic = {true, p.domain.periodic_y, true};
  if (!p.domain.periodic_y) {
    c.walls.push_back(PlaneWall{0.0, 0.0, 0.0, 0.0, 1.0, 0.0});
    c.walls.push_back(PlaneWall{0.0, p.domain.width_y_m, 0.0, 0.0, -1.0, 0.0});
  }
  c.gravity_m_s2 = p.gravity_vector();
  c.dt_s = p.time.dt_dem_s;
  c.skin_m = p.numerics.neighbor_skin_m;
  c.slab_excursion_m = 0.5 * c.skin_m;
  c.contact =
      LinearSpringDashpot(p.contact.stiffness_n_m, p.contact.restitution, p.contact.tangential_damping_ratio,
                          p.contact.friction, p.contact.clip_attractive_normal);
  check_contact_model(p.contact.model);
  c.rolling_model = p.contact.rolling_model;
  c.rolling_friction = p.contact.rolling_friction;
  return c;
}

void activate_dem_models(ModelTimers& t, const CaseParams& p) {
  t.activate("dem_contacts", fmt::format("{}, k_n = {} N/m, e = {}, mu = {}{}", p.contact.model,
                                         p.contact.stiffness_n_m, p.contact.restitution, p.contact.friction,
                                         p.contact.clip_attractive_normal ? ", normal force clipped" : ""));
  if (p.contact.rolling_model != "none" && p.contact.rolling_friction > 0.0)
    t.activate("rolling_friction", fmt::format("{}, mu_r = {} (timed with dem_contacts)",
                                               p.contact.rolling_model, p.contact.rolling_friction));
  t.activate("neighbor_search", fmt::format("linked cells + Verlet skin {} m", p.numerics.neighbor_skin_m));
}

}  // namespace boycott::particles
