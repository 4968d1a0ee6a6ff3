#pragma once
// Vreman's subgrid eddy viscosity, a stateless kernel shared by the fluid solver and its tests.
#include <array>
#include <cmath>

namespace boycott::fluid {

/// Model constant c = 2.5 C_s^2 with C_s = 0.17 (Vreman 2004, section 3: "c ~ 2.5 C_s^2",
/// 0.07 used there for the mixing layer).
inline constexpr double kVremanConstant = 0.07;

/// Vreman (2004), Phys. Fluids 16, 3670, Eq. (5) with the anisotropic filter widths of Eq. (7):
///   alpha_ij = d u_j / d x_i,  beta_ij = sum_m Delta_m^2 alpha_mi alpha_mj,
///   B_beta = b11 b22 - b12^2 + b11 b33 - b13^2 + b22 b33 - b23^2,
///   nu_t = c sqrt(B_beta / (alpha_ij alpha_ij)),  0 where alpha_ij alpha_ij = 0.
/// B_beta vanishes whenever the gradient has rank one (any plane shear, e.g. Poiseuille flow),
/// so the model switches itself off in laminar shear layers.
/// `grad[i][j]` = d u_j / d x_i (1/s); `delta_m` the cell sizes (m). Returns m^2/s.
inline double vreman_viscosity(const std::array<std::array<double, 3>, 3>& grad,
                               const std::array<double, 3>& delta_m, double c = kVremanConstant) {
  double aa = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) aa += grad[i][j] * grad[i][j];
  double b[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0.0;
      for (int m = 0; m < 3; ++m) s += delta_m[m] * delta_m[m] * grad[m][i] * grad[m][j];
      b[i][j] = s;
    }
  const double bb = b[0][0] * b[1][1] - b[0][1] * b[0][1] + b[0][0] * b[2][2] - b[0][2] * b[0][2] +
                    b[1][1] * b[2][2] - b[1][2] * b[1][2];
  // Round-off can leave B_beta slightly negative for rank-one gradients; it is >= 0 in exact
  // arithmetic (a sum of 2x2 principal minors of a Gram matrix). A select, not early returns,
  // so that the solver's loop over a row of cells vectorises (the discarded value may be NaN).
  const double d2 = delta_m[0] * delta_m[0] + delta_m[1] * delta_m[1] + delta_m[2] * delta_m[2];
  const bool on = aa > 0.0 && bb > 1e-14 * aa * aa * d2 * d2;
  return on ? c * std::sqrt(bb / aa) : 0.0;
}

}  // namespace boycott::fluid
