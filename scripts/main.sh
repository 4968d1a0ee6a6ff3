#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job: the demo study (studies/demo.toml,
# 4 inclination angles of a small channel, 3 replicas each, a few minutes on 2 cores), then prints
# its curve.
# Running it again resumes or skips what is already in runs/demo.sqlite.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
"$root/scripts/install_deps.sh"
BOYCOTT_BUILD_TARGET=boycott "$root/scripts/build.sh"
mkdir -p "$root/runs"
cd "$root/runs"
"$root/build/driver/boycott" study run "$root/studies/demo.toml" --db demo.sqlite --jobs 2
