#include "fluid/spectral_poisson_pc.hpp"

#include <fftw3-mpi.h>
#include <fftw3.h>

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace boycott::fluid {

namespace {
constexpr double kTwoPi = 6.283185307179586476925286766559;
}

namespace {

/// Orthonormal eigenvectors qy[j * ny + m] of the 1-D y operator and their eigenvalues sy[m] for
/// a unit coefficient (-1 marks an unused mode). Walls (cell-centred Neumann): cos(pi m (j + 1/2)
/// / ny), eigenvalue 2 - 2 cos(pi m / ny). Periodic: the real Fourier basis, eigenvalue
/// 2 - 2 cos(2 pi m' / ny). Also 2 - 2 cos(2 pi k / n) per x and z wavenumber.
void make_bases(int nx, int ny, int nz, bool periodic_y, std::vector<double>& qy, std::vector<double>& sy,
                std::vector<double>& sx, std::vector<double>& sz) {
  qy.assign(static_cast<std::size_t>(ny) * ny, 0.0);
  sy.assign(ny, 0.0);
  for (int m = 0; m < ny; ++m) {
    for (int j = 0; j < ny; ++j) {
      double v;
      if (!periodic_y) {
        v = std::cos(M_PI * m * (j + 0.5) / ny);
      } else {
        // m = 0: constant; odd m -> cos of wavenumber (m+1)/2, even m -> sin of wavenumber m/2
        const int w = (m + 1) / 2;
        v = (m % 2 == 1) ? std::cos(kTwoPi * w * j / ny) : (m == 0 ? 1.0 : std::sin(kTwoPi * w * j / ny));
      }
      qy[static_cast<std::size_t>(j) * ny + m] = v;
    }
    sy[m] =
        periodic_y ? 2.0 - 2.0 * std::cos(kTwoPi * ((m + 1) / 2) / ny) : 2.0 - 2.0 * std::cos(M_PI * m / ny);
    double nrm = 0.0;
    for (int j = 0; j < ny; ++j)
      nrm += qy[static_cast<std::size_t>(j) * ny + m] * qy[static_cast<std::size_t>(j) * ny + m];
    if (nrm < 1e-12) {  // the sine of the Nyquist wavenumber vanishes on the grid: unused mode
      sy[m] = -1.0;
      continue;
    }
    nrm = 1.0 / std::sqrt(nrm);
    for (int j = 0; j < ny; ++j) qy[static_cast<std::size_t>(j) * ny + m] *= nrm;
  }
  const int nkx = nx / 2 + 1;
  sx.resize(nkx);
  for (int k = 0; k < nkx; ++k) sx[k] = 2.0 - 2.0 * std::cos(kTwoPi * k / nx);
  sz.resize(nz);
  for (int k = 0; k < nz; ++k) sz[k] = 2.0 - 2.0 * std::cos(kTwoPi * k / nz);
}

/// The y part of the inverse on ny rows of n2 doubles (complex values, re and im interleaved; row
/// j at rows + j * stride): to the y eigenbasis, times scale / lambda, back, where
/// lambda = ca sa[p] + kb + cy sy[m] for complex entry p (the x or z part varying along the row,
/// the other one constant). The zero eigenvalue
/// (the constant, the null space of the pure-Neumann/periodic system) and unused modes give 0.
/// The loops run along the rows (contiguous) and vectorise; each value is summed over j and m in
/// index order. eig: scratch of ny * n2.
void solve_y_rows(const std::vector<double>& qy, const std::vector<double>& sy, double* rows,
                  std::size_t stride, int n2, double ca, const double* sa, double kb, double cy, double scale,
                  double tiny, double* __restrict eig) {
  const int ny = static_cast<int>(sy.size());
  for (int m = 0; m < ny; ++m) {
    double* __restrict e = eig + static_cast<std::size_t>(m) * n2;
    for (int q = 0; q < n2; ++q) e[q] = 0.0;
    for (int j = 0; j < ny; ++j) {
      const double w = qy[static_cast<std::size_t>(j) * ny + m];
      const double* __restrict row = rows + j * stride;
#pragma GCC ivdep
      for (int q = 0; q < n2; ++q) e[q] += w * row[q];
    }
    const bool unused = sy[m] < 0.0;
#pragma GCC ivdep
    for (int p = 0; p < n2 / 2; ++p) {
      // Explicit fused multiply-adds: what GCC made of this sum before the kernel was shared
      // (contracted, with cy sy[m] kept in the loop). Here it would hoist cy sy[m] and round it
      // separately, and one rank's results would change in the last bit.
      const double lam = std::fma(cy, sy[m], std::fma(ca, sa[p], kb));
      const double f = (unused || lam <= tiny) ? 0.0 : scale / lam;
      e[2 * p] *= f;
      e[2 * p + 1] *= f;
    }
  }
  for (int j = 0; j < ny; ++j) {
    double* __restrict row = rows + j * stride;
    for (int q = 0; q < n2; ++q) row[q] = 0.0;
    for (int m = 0; m < ny; ++m) {
      const double w = qy[static_cast<std::size_t>(j) * ny + m];
      const double* __restrict e = eig + static_cast<std::size_t>(m) * n2;
#pragma GCC ivdep
      for (int q = 0; q < n2; ++q) row[q] += w * e[q];
    }
  }
}

}  // namespace

SpectralPoissonPreconditioner::SpectralPoissonPreconditioner(int nx, int ny, int nz, bool periodic_y)
    : nx_(nx), ny_(ny), nz_(nz), nkx_(nx / 2 + 1), periodic_y_(periodic_y) {
  if (nx < 1 || ny < 1 || nz < 1) throw std::invalid_argument("SpectralPoissonPreconditioner: empty grid");
  make_bases(nx, ny, nz, periodic_y, qy_, sy_, sx_, sz_);

  const std::size_t nreal = static_cast<std::size_t>(ny) * nz * nx;
  const std::size_t ncplx = static_cast<std::size_t>(ny) * nz * nkx_;
  real_ = fftw_alloc_real(nreal);
  auto* spec = fftw_alloc_complex(ncplx);
  spec_ = spec;
  eig_.resize(static_cast<std::size_t>(ny) * 2 * nkx_);
  int n[2] = {nz, nx};
  // FFTW_ESTIMATE: plans in microseconds; MEASURE would time candidate plans at every start.
  fwd_ = fftw_plan_many_dft_r2c(2, n, ny, real_, nullptr, 1, nz * nx, spec, nullptr, 1, nz * nkx_,
                                FFTW_ESTIMATE);
  bwd_ = fftw_plan_many_dft_c2r(2, n, ny, spec, nullptr, 1, nz * nkx_, real_, nullptr, 1, nz * nx,
                                FFTW_ESTIMATE);
  if (!fwd_ || !bwd_) throw std::runtime_error("SpectralPoissonPreconditioner: FFTW plan failed");
}

SpectralPoissonPreconditioner::~SpectralPoissonPreconditioner() {
  if (fwd_) fftw_destroy_plan(static_cast<fftw_plan>(fwd_));
  if (bwd_) fftw_destroy_plan(static_cast<fftw_plan>(bwd_));
  fftw_free(real_);
  fftw_free(spec_);
}

void SpectralPoissonPreconditioner::set_coefficients(double cx, double cy, double cz) {
  c_ = {cx, cy, cz};
}

void SpectralPoissonPreconditioner::apply(const double* r, double* z) {
  const std::size_t plane = static_cast<std::size_t>(nz_) * nx_;
  // r[i + nx (j + ny k)] -> real_[j][k][i]
  for (int k = 0; k < nz_; ++k)
    for (int j = 0; j < ny_; ++j)
      std::memcpy(real_ + j * plane + static_cast<std::size_t>(k) * nx_,
                  r + static_cast<std::size_t>(nx_) * (j + static_cast<std::size_t>(ny_) * k),
                  sizeof(double) * nx_);
  fftw_execute(static_cast<fftw_plan>(fwd_));
  auto* spec = reinterpret_cast<std::complex<double>*>(spec_);
  const std::size_t cplane = static_cast<std::size_t>(nz_) * nkx_;
  // Per (kz, kx): to the y eigenbasis, divide by the eigenvalue, back; a whole kx row at a time.
  const double scale = 1.0 / (static_cast<double>(nx_) * nz_);
  const double tiny = 1e-12 * (c_[0] + c_[1] + c_[2]);
  auto* sp = reinterpret_cast<double*>(spec);
  for (int kz = 0; kz < nz_; ++kz) {
    solve_y_rows(qy_, sy_, sp + 2 * static_cast<std::size_t>(kz) * nkx_, 2 * cplane, 2 * nkx_, c_[0],
                 sx_.data(), c_[2] * sz_[kz], c_[1], scale, tiny, eig_.data());
  }
  fftw_execute(static_cast<fftw_plan>(bwd_));
  for (int k = 0; k < nz_; ++k)
    for (int j = 0; j < ny_; ++j)
      std::memcpy(z + static_cast<std::size_t>(nx_) * (j + static_cast<std::size_t>(ny_) * k),
                  real_ + j * plane + static_cast<std::size_t>(k) * nx_, sizeof(double) * nx_);
}

}  // namespace boycott::fluid

namespace boycott::fluid {

namespace {
void init_fftw_mpi() {
  static const bool initialised = [] {
    fftw_mpi_init();
    return true;
  }();
  (void)initialised;
}
}  // namespace

std::vector<int> DistributedSpectralPoisson::z_slab_counts(int nx, int ny, int nz, MPI_Comm comm) {
  init_fftw_mpi();
  const ptrdiff_t nc[2] = {nz, nx / 2 + 1};
  ptrdiff_t n0, s0, n1, s1;
  fftw_mpi_local_size_many_transposed(2, nc, ny, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, comm, &n0,
                                      &s0, &n1, &s1);
  int size = 1;
  MPI_Comm_size(comm, &size);
  std::vector<int> counts(static_cast<std::size_t>(size));
  const int mine = static_cast<int>(n0);
  MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  return counts;
}

DistributedSpectralPoisson::DistributedSpectralPoisson(int nx, int ny, int nz, bool periodic_y, MPI_Comm comm)
    : nx_(nx), ny_(ny), nz_(nz), nkx_(nx / 2 + 1) {
  if (nx < 1 || ny < 1 || nz < 1) throw std::invalid_argument("DistributedSpectralPoisson: empty grid");
  init_fftw_mpi();
  make_bases(nx, ny, nz, periodic_y, qy_, sy_, sx_, sz_);
  const ptrdiff_t nc[2] = {nz, nkx_};  // complex extents for the r2c local sizes
  ptrdiff_t n0, s0, n1, s1;
  const ptrdiff_t alloc = fftw_mpi_local_size_many_transposed(
      2, nc, ny, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, comm, &n0, &s0, &n1, &s1);
  z0_ = static_cast<int>(s0), nz_local_ = static_cast<int>(n0);
  kx0_ = static_cast<int>(s1), nkx_local_ = static_cast<int>(n1);
  real_ = fftw_alloc_real(2 * static_cast<std::size_t>(alloc > 0 ? alloc : 1));
  auto* spec = fftw_alloc_complex(static_cast<std::size_t>(alloc > 0 ? alloc : 1));
  spec_ = spec;
  eig_.resize(static_cast<std::size_t>(ny) * 2 * nz);
  rows_.resize(static_cast<std::size_t>(ny) * 2 * nz);
  const ptrdiff_t nr[2] = {nz, nx};
  fwd_ = fftw_mpi_plan_many_dft_r2c(2, nr, ny, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, real_, spec,
                                    comm, FFTW_ESTIMATE | FFTW_MPI_TRANSPOSED_OUT);
  bwd_ = fftw_mpi_plan_many_dft_c2r(2, nr, ny, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, spec, real_,
                                    comm, FFTW_ESTIMATE | FFTW_MPI_TRANSPOSED_IN);
  if (!fwd_ || !bwd_) throw std::runtime_error("DistributedSpectralPoisson: FFTW MPI plan failed");
}

DistributedSpectralPoisson::~DistributedSpectralPoisson() {
  if (fwd_) fftw_destroy_plan(static_cast<fftw_plan>(fwd_));
  if (bwd_) fftw_destroy_plan(static_cast<fftw_plan>(bwd_));
  fftw_free(real_);
  fftw_free(spec_);
}

void DistributedSpectralPoisson::apply(const double* r, double* z) {
  const std::size_t nxp = 2 * static_cast<std::size_t>(nkx_);  // padded x extent of the real array
  // slab [k][j][i] -> real_[(k nxp + i) ny + j]
  for (int k = 0; k < nz_local_; ++k)
    for (int j = 0; j < ny_; ++j) {
      const double* src = r + static_cast<std::size_t>(nx_) * (j + static_cast<std::size_t>(ny_) * k);
      double* dst = real_ + static_cast<std::size_t>(k) * nxp * ny_ + j;
      for (int i = 0; i < nx_; ++i) dst[static_cast<std::size_t>(i) * ny_] = src[i];
    }
  fftw_execute(static_cast<fftw_plan>(fwd_));
  // FFTW's transposed output holds, per local kx, nz columns of ny (y innermost): move each kx
  // block to ny rows over kz, so that the y solve runs along contiguous rows as in the serial
  // preconditioner (same arithmetic, same order), and back.
  auto* sp = reinterpret_cast<double*>(spec_);
  const double scale = 1.0 / (static_cast<double>(nx_) * nz_);
  const double tiny = 1e-12 * (c_[0] + c_[1] + c_[2]);
  const std::size_t n2 = 2 * static_cast<std::size_t>(nz_);
  double* __restrict rows = rows_.data();
  for (int a = 0; a < nkx_local_; ++a) {
    const int kx = kx0_ + a;
    double* block = sp + static_cast<std::size_t>(a) * n2 * ny_;  // [kz][j] complex
    for (int kz = 0; kz < nz_; ++kz)
      for (int j = 0; j < ny_; ++j) {
        rows[j * n2 + 2 * kz] = block[(static_cast<std::size_t>(kz) * ny_ + j) * 2];
        rows[j * n2 + 2 * kz + 1] = block[(static_cast<std::size_t>(kz) * ny_ + j) * 2 + 1];
      }
    solve_y_rows(qy_, sy_, rows, n2, static_cast<int>(n2), c_[2], sz_.data(), c_[0] * sx_[kx], c_[1], scale,
                 tiny, eig_.data());
    for (int kz = 0; kz < nz_; ++kz)
      for (int j = 0; j < ny_; ++j) {
        block[(static_cast<std::size_t>(kz) * ny_ + j) * 2] = rows[j * n2 + 2 * kz];
        block[(static_cast<std::size_t>(kz) * ny_ + j) * 2 + 1] = rows[j * n2 + 2 * kz + 1];
      }
  }
  fftw_execute(static_cast<fftw_plan>(bwd_));
  for (int k = 0; k < nz_local_; ++k)
    for (int j = 0; j < ny_; ++j) {
      double* dst = z + static_cast<std::size_t>(nx_) * (j + static_cast<std::size_t>(ny_) * k);
      const double* src = real_ + static_cast<std::size_t>(k) * nxp * ny_ + j;
      for (int i = 0; i < nx_; ++i) dst[i] = src[static_cast<std::size_t>(i) * ny_];
    }
}

}  // namespace boycott::fluid
