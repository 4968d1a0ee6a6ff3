#!/usr/bin/env bash
# Installs what is missing, builds, and runs the quick test suite (the one CI runs).
# Long validation tests: scripts/test.sh -L long   (any ctest arguments are passed on)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# Slurm and munge (daemons) only where the Slurm test must run: CI sets BOYCOTT_REQUIRE_SLURM=1;
# elsewhere that test skips with its reason when Slurm is absent.
if [ "${BOYCOTT_REQUIRE_SLURM:-0}" = 1 ]; then "$root/scripts/install_deps.sh" --with-slurm; else "$root/scripts/install_deps.sh"; fi
"$root/scripts/build.sh"
cd "$root/build"
if [ $# -eq 0 ]; then set -- -L quick; fi
ctest --output-on-failure -j 2 --timeout 900 "$@"
