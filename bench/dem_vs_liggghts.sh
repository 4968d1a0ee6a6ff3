#!/usr/bin/env bash
# Runs the dry particle benchmark (../shared/bench/liggghts/in.bed) on our engine and on
# LIGGGHTS in the same run, each on one core, and prints ns per particle-step for both; the last
# line is speedup_vs_liggghts=X (LIGGGHTS time / ours).
# Usage: bench/dem_vs_liggghts.sh            (builds first if needed; needs Debian's liggghts)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
deck="$root/../shared/bench/liggghts/run.sh"
[ -x "$root/build/bench/bench_dem" ] || "$root/scripts/build.sh"
command -v liggghts >/dev/null || { apt-get install -y -qq liggghts >/dev/null; }
ours=$(taskset -c 0 "$root/build/bench/bench_dem")
echo "$ours"
theirs=$(bash "$deck" | tail -1)
echo "$theirs"
a=$(sed -n 's/.*ns_per_particle_step=\([0-9.]*\).*/\1/p' <<<"$ours")
b=$(sed -n 's/.*ns_per_particle_step=\([0-9.]*\).*/\1/p' <<<"$theirs")
python3 -c "print(f'speedup_vs_liggghts={$b/$a:.2f}')"
