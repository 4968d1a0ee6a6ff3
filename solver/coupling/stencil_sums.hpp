#pragma once
// The sums of the coupling over a particle's separable stencil (kernels.hpp, sampling.hpp): the
// fluid sampled at a particle, and what it deposits scattered onto the grid.
#include <cstddef>
#include <vector>

#include "coupling/fluid_fields.hpp"
#include "coupling/kernels.hpp"

namespace boycott::coupling {

/// A particle's separable stencil on one grid array with the periodic wrap and the strides applied
/// once. GridField::index wraps each point with integer divisions, which made sampling ~27 % of a
/// coupled step of the reduced base case; the sums below keep its order (x inside y inside z), so
/// results are unchanged to the bit.
struct Offsets3 {
  int n[3];
  std::size_t off[3][4];  // offset of point a along d into the array (stride included)
  double w[3][4];
};

inline Offsets3 offsets(const Weights1D& wx, const Weights1D& wy, const Weights1D& wz, const GridField& f) {
  Offsets3 o{};
  const Weights1D* W[3] = {&wx, &wy, &wz};
  const int dim[3] = {f.nx, f.ny, f.nz};
  const std::size_t stride[3] = {1, static_cast<std::size_t>(f.nx), static_cast<std::size_t>(f.nx) * f.ny};
  for (int d = 0; d < 3; ++d) {
    o.n[d] = W[d]->n;
    // A window of planes (several ranks) is indexed from its first plane.
    const int first = W[d]->first - (d == 2 ? f.k0 : 0);
    for (int a = 0; a < W[d]->n; ++a) {
      const int i = f.periodic[d] ? GridField::wrap(first + a, dim[d]) : first + a;
      o.off[d][a] = static_cast<std::size_t>(i) * stride[d];
      o.w[d][a] = W[d]->w[a];
    }
  }
  return o;
}

/// For each of N fields that share one layout, the sum over the stencil of
/// w_x(i) w_y(j) w_z(k) f(i,j,k) (x inside y inside z), in one pass: the offsets and weights are
/// read once for all of them, and each field's sums run in the same order as alone.
template <int N>
inline void sample_fields(const Offsets3& o, const double* const (&f)[N], double (&out)[N]) {
  double s[N] = {};
  for (int c = 0; c < o.n[2]; ++c) {
    double sy[N] = {};
    for (int b = 0; b < o.n[1]; ++b) {
      const std::size_t row = o.off[2][c] + o.off[1][b];
      double sx[N] = {};
      for (int a = 0; a < o.n[0]; ++a) {
        const std::size_t q = row + o.off[0][a];
        for (int m = 0; m < N; ++m) sx[m] += o.w[0][a] * f[m][q];
      }
      for (int m = 0; m < N; ++m) sy[m] += o.w[1][b] * sx[m];
    }
    for (int m = 0; m < N; ++m) s[m] += o.w[2][c] * sy[m];
  }
  for (int m = 0; m < N; ++m) out[m] = s[m];
}

/// Sum over the stencil of w_x(i) w_y(j) w_z(k) f(i,j,k).
inline double sample(const Offsets3& o, const std::vector<double>& field) {
  const double* const f[1] = {field.data()};
  double v[1];
  sample_fields(o, f, v);
  return v[0];
}

/// Calls f(index, w_x w_y w_z) for every stencil point.
template <class F>
inline void scatter(const Offsets3& o, F&& f) {
  for (int c = 0; c < o.n[2]; ++c)
    for (int b = 0; b < o.n[1]; ++b)
      for (int a = 0; a < o.n[0]; ++a)
        f(o.off[2][c] + o.off[1][b] + o.off[0][a], o.w[0][a] * o.w[1][b] * o.w[2][c]);
}

}  // namespace boycott::coupling
