#include "fluid/spectral_poisson_pc.hpp"

#include <fftw3-mpi.h>
#include <fftw3.h>

#include <algorithm>
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

/// To (forward) or from the y eigenbasis: ny rows of n2 doubles (complex values, re and im
/// interleaved; row j of `in` at in + j * in_stride) to ny rows of `out` (at out_stride):
/// out row m = sum_j qy[j][m] in row j (forward), out row j = sum_m qy[j][m] in row m (back).
/// The loops run along the rows (contiguous) and vectorise; each value is summed in index order.
void y_basis(const std::vector<double>& qy, int ny, const double* in, std::size_t in_stride, double* out,
             std::size_t out_stride, std::size_t n2, bool forward) {
  for (int a = 0; a < ny; ++a) {
    double* __restrict o = out + a * out_stride;
    for (std::size_t q = 0; q < n2; ++q) o[q] = 0.0;
    for (int b = 0; b < ny; ++b) {
      const double w =
          forward ? qy[static_cast<std::size_t>(b) * ny + a] : qy[static_cast<std::size_t>(a) * ny + b];
      const double* __restrict r = in + b * in_stride;
#pragma GCC ivdep
      for (std::size_t q = 0; q < n2; ++q) o[q] += w * r[q];
    }
  }
}

/// Multiplies count complex entries (x wavenumbers kx .. kx + count - 1, sx from kx) of y mode m
/// and z wavenumber kz by scale / lambda, lambda = c_x sx[kx] + c_z sz[kz] + c_y sy[m]; the zero
/// eigenvalue (the constant, the null space of the pure-Neumann/periodic system) and unused modes
/// (sy < 0) give 0. kb = c_z sz[kz].
void divide_by_eigenvalue(double* __restrict row, int count, const std::array<double, 3>& c,
                          const double* __restrict sx, double kb, double sym, double scale, double tiny) {
  const bool unused = sym < 0.0;
#pragma GCC ivdep
  for (int p = 0; p < count; ++p) {
    // Explicit fused multiply-adds: what GCC made of this sum before the kernel was shared
    // (contracted, with c_y sy[m] kept in the loop). Here it would hoist c_y sy[m] and round it
    // separately, and one rank's results would change in the last bit.
    const double lam = std::fma(c[1], sym, std::fma(c[0], sx[p], kb));
    const double f = (unused || lam <= tiny) ? 0.0 : scale / lam;
    row[2 * p] *= f;
    row[2 * p + 1] *= f;
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
  const std::size_t n2 = 2 * static_cast<std::size_t>(nkx_);
  for (int kz = 0; kz < nz_; ++kz) {
    double* rows = sp + 2 * static_cast<std::size_t>(kz) * nkx_;  // ny rows, 2 cplane apart
    y_basis(qy_, ny_, rows, 2 * cplane, eig_.data(), n2, n2, true);
    for (int m = 0; m < ny_; ++m)
      divide_by_eigenvalue(eig_.data() + m * n2, nkx_, c_, sx_.data(), c_[2] * sz_[kz], sy_[m], scale, tiny);
    y_basis(qy_, ny_, eig_.data(), n2, rows, 2 * cplane, n2, false);
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
    : nx_(nx), ny_(ny), nz_(nz), nkx_(nx / 2 + 1), comm_(comm) {
  if (nx < 1 || ny < 1 || nz < 1) throw std::invalid_argument("DistributedSpectralPoisson: empty grid");
  make_bases(nx, ny, nz, periodic_y, qy_, sy_, sx_, sz_);
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  // z-planes: FFTW's slabs (the fluid grid's layout); kx: near-equal blocks.
  const std::vector<int> zc = z_slab_counts(nx, ny, nz, comm);
  std::vector<int> zs(size), kc(size), ks(size);
  for (int r = 0, z = 0, k = 0; r < size; ++r) {
    zs[r] = z, z += zc[r];
    kc[r] = nkx_ / size + (r < nkx_ % size ? 1 : 0);
    ks[r] = k, k += kc[r];
  }
  z0_ = zs[rank], nz_local_ = zc[rank], kx0_ = ks[rank], nkx_local_ = kc[rank];
  // Message sizes in doubles: a slab's [k][m][kx block] to each rank, whole [kz][m][kx] back.
  send_count_.resize(size), send_first_.resize(size), recv_count_.resize(size), recv_first_.resize(size);
  for (int q = 0, a = 0, b = 0; q < size; ++q) {
    send_count_[q] = 2 * nz_local_ * ny * kc[q], send_first_[q] = a, a += send_count_[q];
    recv_count_[q] = 2 * zc[q] * ny * nkx_local_, recv_first_[q] = b, b += recv_count_[q];
  }
  block_first_ = ks, block_count_ = kc;
  const std::size_t rows = static_cast<std::size_t>(nz_local_) * ny;   // x rows of this slab
  const std::size_t cols = static_cast<std::size_t>(ny) * nkx_local_;  // z columns of this kx block
  real_ = fftw_alloc_real(std::max<std::size_t>(1, rows * nx));
  spec_ = fftw_alloc_complex(std::max<std::size_t>(1, rows * nkx_));
  eig_.resize(rows * 2 * nkx_);
  packed_.resize(rows * 2 * nkx_);
  zcols_ = fftw_alloc_complex(std::max<std::size_t>(1, cols * nz));
  auto* spec = static_cast<fftw_complex*>(spec_);
  auto* zcol = static_cast<fftw_complex*>(zcols_);
  // FFTW_ESTIMATE (as the serial preconditioner): deterministic plans, so runs repeat bit for bit.
  const int n_x[1] = {nx}, n_z[1] = {nz};
  if (rows > 0) {
    fwd_x_ = fftw_plan_many_dft_r2c(1, n_x, (int)rows, real_, nullptr, 1, nx, spec, nullptr, 1, nkx_,
                                    FFTW_ESTIMATE);
    bwd_x_ = fftw_plan_many_dft_c2r(1, n_x, (int)rows, spec, nullptr, 1, nkx_, real_, nullptr, 1, nx,
                                    FFTW_ESTIMATE);
    if (!fwd_x_ || !bwd_x_) throw std::runtime_error("DistributedSpectralPoisson: FFTW plan failed");
  }
  if (cols > 0) {
    // [kz][m][kx]: column (m, kx) has stride cols, neighbouring columns are adjacent (FFTW
    // vectorises across them), and each rank's slab arrives as one contiguous block.
    fwd_z_ = fftw_plan_many_dft(1, n_z, (int)cols, zcol, nullptr, (int)cols, 1, zcol, nullptr, (int)cols, 1,
                                FFTW_FORWARD, FFTW_ESTIMATE);
    bwd_z_ = fftw_plan_many_dft(1, n_z, (int)cols, zcol, nullptr, (int)cols, 1, zcol, nullptr, (int)cols, 1,
                                FFTW_BACKWARD, FFTW_ESTIMATE);
    if (!fwd_z_ || !bwd_z_) throw std::runtime_error("DistributedSpectralPoisson: FFTW plan failed");
  }
}

DistributedSpectralPoisson::~DistributedSpectralPoisson() {
  for (void* p : {fwd_x_, bwd_x_, fwd_z_, bwd_z_})
    if (p) fftw_destroy_plan(static_cast<fftw_plan>(p));
  fftw_free(real_);
  fftw_free(spec_);
  fftw_free(zcols_);
}

void DistributedSpectralPoisson::apply(const double* r, double* z) {
  // The transform is separable: x by FFT on each rank's own rows, y by the eigenvectors on the
  // same rows, then one all-to-all gives each rank whole z columns of its kx block for the z FFT
  // and the division by the eigenvalue, and a second one brings them back. Half the data of a
  // 2-D transform crosses ranks, once each way, in two messages per pair of ranks.
  const int size = static_cast<int>(send_count_.size());
  const std::size_t rows = static_cast<std::size_t>(nz_local_) * ny_, nx = static_cast<std::size_t>(nx_);
  const std::size_t n2 = 2 * static_cast<std::size_t>(nkx_), plane = static_cast<std::size_t>(ny_) * n2;
  auto* spec = static_cast<double*>(spec_);
  double* __restrict eig = eig_.data();
  double* __restrict packed = packed_.data();
  auto* zc = static_cast<double*>(zcols_);
  if (rows > 0) {
    std::memcpy(real_, r, sizeof(double) * rows * nx);
    fftw_execute(static_cast<fftw_plan>(fwd_x_));
  }
  for (int k = 0; k < nz_local_; ++k) y_basis(qy_, ny_, spec + k * plane, n2, eig + k * plane, n2, n2, true);
  // To rank q: [k][m][its kx block].
  double* out = packed;
  for (int q = 0; q < size; ++q) {
    const std::size_t len = 2 * static_cast<std::size_t>(block_count_[q]);
    for (std::size_t row = 0; row < rows; ++row, out += len)
      std::memcpy(out, eig + row * n2 + 2 * static_cast<std::size_t>(block_first_[q]), sizeof(double) * len);
  }
  MPI_Alltoallv(packed, send_count_.data(), send_first_.data(), MPI_DOUBLE, zc, recv_count_.data(),
                recv_first_.data(), MPI_DOUBLE, comm_);
  const std::size_t cols = static_cast<std::size_t>(ny_) * nkx_local_;
  if (cols > 0) {
    fftw_execute(static_cast<fftw_plan>(fwd_z_));
    const double scale = 1.0 / (static_cast<double>(nx_) * nz_);
    const double tiny = 1e-12 * (c_[0] + c_[1] + c_[2]);
    for (int kz = 0; kz < nz_; ++kz)
      for (int m = 0; m < ny_; ++m)
        divide_by_eigenvalue(zc + 2 * ((static_cast<std::size_t>(kz) * ny_ + m) * nkx_local_), nkx_local_, c_,
                             sx_.data() + kx0_, c_[2] * sz_[kz], sy_[m], scale, tiny);
    fftw_execute(static_cast<fftw_plan>(bwd_z_));
  }
  MPI_Alltoallv(zc, recv_count_.data(), recv_first_.data(), MPI_DOUBLE, packed, send_count_.data(),
                send_first_.data(), MPI_DOUBLE, comm_);
  const double* in = packed;
  for (int q = 0; q < size; ++q) {
    const std::size_t len = 2 * static_cast<std::size_t>(block_count_[q]);
    for (std::size_t row = 0; row < rows; ++row, in += len)
      std::memcpy(eig + row * n2 + 2 * static_cast<std::size_t>(block_first_[q]), in, sizeof(double) * len);
  }
  for (int k = 0; k < nz_local_; ++k) y_basis(qy_, ny_, eig + k * plane, n2, spec + k * plane, n2, n2, false);
  if (rows > 0) {
    fftw_execute(static_cast<fftw_plan>(bwd_x_));
    std::memcpy(z, real_, sizeof(double) * rows * nx);
  }
}

}  // namespace boycott::fluid
