#pragma once
#include <numbers>

namespace boycott {
inline constexpr double kPi = std::numbers::pi;
/// Standard gravity, m/s^2 (the paper's g; Ga = sqrt(g W^3)/nu = 1456 for the base case uses 9.81).
inline constexpr double kStandardGravity = 9.81;
}  // namespace boycott
