#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
"$root/scripts/install_deps.sh"
"$root/scripts/build.sh"
# For now the main job is the dry DEM scene of the benchmark problem; the demo study replaces it
# once the coupled solver and the driver land.
"$root/build/driver/boycott" case run "$root/studies/cases/dem_only.toml" --out "$root/runs/dem_only"
cat "$root/runs/dem_only/summary.json"
