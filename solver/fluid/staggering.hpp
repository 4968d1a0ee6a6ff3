#pragma once
// The staggering convention of the fluid grid (fluid_solver.hpp): the value stored at cell
// (i, j, k) of a face field lives on that cell's lower face in its direction, so the neighbour
// across that face is (i, j, k) - kE[d].
namespace boycott::fluid {

/// Unit offsets per direction: kE[d][e] = 1 when e == d.
constexpr int kE[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

}  // namespace boycott::fluid
