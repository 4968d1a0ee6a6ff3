// Spectral preconditioner for the pressure-correction system: the exact inverse of
// the constant-coefficient 7-point operator with the domain-mean face coefficient of each
// direction, by FFT in the periodic x and z directions and the eigenvectors of the 1-D y
// operator (cell-centred Neumann walls or periodic). The real system has alpha_f D on its faces
// (alpha_f 0.4-1 beside a bed), so this is a preconditioner, not a solver: Krylov iterations
// then depend only on that contrast, and one application is a few FFTs, with no set-up beyond
// the FFTW plans (BoomerAMG's set-up alone was ~150 ms per step on the 200 x 6 x 100 mesh).
#pragma once

#include <mpi.h>

#include <array>
#include <complex>
#include <vector>

namespace boycott::fluid {

class SpectralPoissonPreconditioner {
 public:
  /// Cells nx, ny, nz; x and z periodic, y periodic or walls. Layout of apply()'s vectors:
  /// i + nx (j + ny k), PETSc's DMDA order on one rank.
  SpectralPoissonPreconditioner(int nx, int ny, int nz, bool periodic_y);
  ~SpectralPoissonPreconditioner();
  SpectralPoissonPreconditioner(const SpectralPoissonPreconditioner&) = delete;
  SpectralPoissonPreconditioner& operator=(const SpectralPoissonPreconditioner&) = delete;

  /// Face coefficients of the operator in 1/m^2 (units of the matrix entries): sum over the
  /// faces of c_d (p_cell - p_neighbour), walls carrying none.
  void set_coefficients(double cx, double cy, double cz);
  /// z = M^+ r: the constant (null-space) component of r is dropped, z has zero mean.
  void apply(const double* r, double* z);

 private:
  int nx_, ny_, nz_, nkx_;
  bool periodic_y_;
  std::array<double, 3> c_{1.0, 1.0, 1.0};
  std::vector<double> qy_;       ///< orthonormal eigenvectors of the 1-D y operator, [j * ny + m]
  std::vector<double> sy_;       ///< their eigenvalues for a unit coefficient
  std::vector<double> sx_, sz_;  ///< 2 - 2 cos(2 pi k / n) per x and z wavenumber
  double* real_ = nullptr;       ///< ny planes of nz x nx reals (fftw_malloc)
  void* spec_ = nullptr;         ///< ny planes of nz x (nx/2+1) complex (fftw_complex)
  std::vector<double> eig_;      ///< one kz row of coefficients in the y eigenbasis: ny x (re, im) x nkx
  void* fwd_ = nullptr;          ///< fftw_plan
  void* bwd_ = nullptr;
};

/// The same preconditioner on several ranks. Each rank holds a slab of whole z-planes, k in
/// [z_begin, z_begin + z_count), in natural order i + nx (j + ny (k - z_begin)); the slabs are
/// FFTW's MPI slabs (z_slab_counts), the layout of the fluid grid. An application transforms x
/// and y on the slab, exchanges once with every rank (all-to-all) for whole z columns of a block
/// of x wavenumbers, and back; FFTW's own MPI 2-D transform of the same data, y interleaved, was
/// ~1.5x slower on 2 ranks and barely faster than one rank's serial transform.
class DistributedSpectralPoisson {
 public:
  DistributedSpectralPoisson(int nx, int ny, int nz, bool periodic_y, MPI_Comm comm);
  ~DistributedSpectralPoisson();
  DistributedSpectralPoisson(const DistributedSpectralPoisson&) = delete;
  DistributedSpectralPoisson& operator=(const DistributedSpectralPoisson&) = delete;

  int z_begin() const { return z0_; }
  int z_count() const { return nz_local_; }
  /// The z-planes each rank of `comm` holds in FFTW's slabs for this grid (collective): a DMDA
  /// laid out with these z ownership ranges, undivided in x and y, stores its global vector in
  /// exactly this class's slab order, so the preconditioner needs no scatter.
  static std::vector<int> z_slab_counts(int nx, int ny, int nz, MPI_Comm comm);
  void set_coefficients(double cx, double cy, double cz) { c_ = {cx, cy, cz}; }
  /// z = M^+ r on this rank's slab (collective).
  void apply(const double* r_slab, double* z_slab);

 private:
  int nx_, ny_, nz_, nkx_;
  MPI_Comm comm_;
  int z0_ = 0, nz_local_ = 0, kx0_ = 0, nkx_local_ = 0;
  std::array<double, 3> c_{1.0, 1.0, 1.0};
  std::vector<double> qy_, sy_, sx_, sz_;
  std::vector<int> block_first_, block_count_;                          ///< each rank's kx block
  std::vector<int> send_count_, send_first_, recv_count_, recv_first_;  ///< all-to-all, in doubles
  double* real_ = nullptr;      ///< the slab's x rows, [k][j][i] (fftw_malloc)
  void* spec_ = nullptr;        ///< their transforms, [k][j][kx] complex
  std::vector<double> eig_;     ///< in the y eigenbasis, [k][m][kx] complex
  std::vector<double> packed_;  ///< eig_ by destination rank: [rank][k][m][kx in its block]
  void* zcols_ = nullptr;       ///< this rank's kx block over all z, [kz][m][kx] complex
  void* fwd_x_ = nullptr;       ///< fftw_plans
  void* bwd_x_ = nullptr;
  void* fwd_z_ = nullptr;
  void* bwd_z_ = nullptr;
};

}  // namespace boycott::fluid
