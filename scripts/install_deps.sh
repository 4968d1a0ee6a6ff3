#!/usr/bin/env bash
# Installs the Debian packages the build needs, only when one is missing.
#   scripts/install_deps.sh               the compiler, CMake, PETSc (with hypre and HDF5), Open MPI,
#                                         HDF5, SQLite, CLI11, GoogleTest, toml++, fmt, nlohmann-json,
#                                         FFTW, Boost.Math, Cairo (plots), clang-format (the style test), python3
#   scripts/install_deps.sh --with-slurm  also slurmctld, slurmd, slurm-client and munge, for
#                                         `study submit` and its test (it starts a private cluster)
# scripts/test.sh passes --with-slurm when BOYCOTT_REQUIRE_SLURM=1 (as .ci/run sets it).
set -euo pipefail
pkgs=(build-essential cmake pkg-config git libpetsc-real-dev libhdf5-openmpi-dev openmpi-bin libcli11-dev
      libsqlite3-dev sqlite3 libgtest-dev libtomlplusplus-dev libfmt-dev nlohmann-json3-dev libbenchmark-dev
      libfftw3-dev libfftw3-mpi-dev libboost-math-dev libcairo2-dev nettle-dev clang-format-14 python3)
for a in "$@"; do
  case "$a" in
    --with-slurm) pkgs+=(slurmctld slurmd slurm-client munge) ;;
    *) echo "install_deps.sh: unknown option '$a' (only --with-slurm)" >&2; exit 2 ;;
  esac
done
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
