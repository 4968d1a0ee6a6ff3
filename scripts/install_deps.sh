#!/usr/bin/env bash
# Installs the Debian packages the build needs, only when one is missing.
set -euo pipefail
pkgs=(build-essential cmake pkg-config git libpetsc-real-dev libhdf5-openmpi-dev openmpi-bin libcli11-dev
      libsqlite3-dev sqlite3 libgtest-dev libtomlplusplus-dev libfmt-dev nlohmann-json3-dev libbenchmark-dev
      libfftw3-dev libfftw3-mpi-dev libcairo2-dev clang-format-14 python3 slurmctld slurmd slurm-client munge)
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
