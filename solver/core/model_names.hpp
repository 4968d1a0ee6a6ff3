#pragma once
// One list of names per model kind. Parsing, `case check`, `case keys` and the registries that
// turn a name into code (coupling/drag_laws.hpp, coupling/kernels.hpp, the contact model of
// particles/) all read these lists, and a test checks that each registry knows exactly its list:
// a name is added here and in its registry, nowhere else. Scenes are not listed here: each
// declares itself in its own file (core/scene_specs.hpp).
#include <string>
#include <vector>

namespace boycott {

/// forces.drag
inline const std::vector<std::string>& drag_law_names() {
  static const std::vector<std::string> n = {"difelice_paper", "difelice", "schiller_naumann", "stokes",
                                             "none"};
  return n;
}
/// forces.lift (coupling/lift_laws.hpp)
inline const std::vector<std::string>& lift_law_names() {
  static const std::vector<std::string> n = {"saffman", "saffman_mei", "saffman_mei_continuous", "mclaughlin",
                                             "none"};
  return n;
}
/// numerics.void_fraction_kernel
inline const std::vector<std::string>& kernel_names() {
  static const std::vector<std::string> n = {"trilinear_smoothed", "trilinear", "cell"};
  return n;
}
/// numerics.vorticity (coupling/fluid_fields.hpp)
inline const std::vector<std::string>& vorticity_names() {
  static const std::vector<std::string> n = {"cell_centres", "edges"};
  return n;
}
/// numerics.sampling
inline const std::vector<std::string>& sampling_names() {
  static const std::vector<std::string> n = {"kernel", "trilinear"};
  return n;
}
/// contact.model
inline const std::vector<std::string>& contact_model_names() {
  static const std::vector<std::string> n = {"linear_spring_dashpot"};
  return n;
}
/// contact.rolling_model
inline const std::vector<std::string>& rolling_model_names() {
  static const std::vector<std::string> n = {"constant_directional", "none"};
  return n;
}
/// fluid.subgrid_model
inline const std::vector<std::string>& subgrid_model_names() {
  static const std::vector<std::string> n = {"vreman", "none"};
  return n;
}

}  // namespace boycott
