#!/usr/bin/env bash
# CFD steps on the paper's mesh (200 x 6 x 100) on 1 and 2 MPI ranks, after 50 warm-up steps.
#   bench/cfd_steps.sh [build_dir=build] [timed_steps=50] [extra PETSc options...]
set -euo pipefail
build=${1:-build}
steps=${2:-50}
shift $(( $# > 2 ? 2 : $# )) || true
bin="$build/bench/boycott_bench_cfd"
[ -x "$bin" ] || { echo "build $bin first (cmake --build $build --target boycott_bench_cfd)" >&2; exit 1; }
for n in 1 2; do
  mpirun --allow-run-as-root --oversubscribe -n "$n" "$bin" "$steps" 50 "$@"
done
