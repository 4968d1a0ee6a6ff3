#!/usr/bin/env bash
# The dry particle problem of ../shared/bench/liggghts/in.bed (d = 0.6 mm, Table III contacts,
# 65 deg, Stokes drag against still water, solid fraction 0.113) at several particle counts, on
# our engine and on Debian's LIGGGHTS 3.8 in the same run, each pinned to one core. The channel
# keeps its 6 mm width and grows in x and z with the count: 15 000 in 0.05 x 0.05 m (the deck;
# fewer in 0.05 m x a shorter z),
# N > 15 000 in 0.2 m x (0.05 x 0.05 x N / 15 000 / 0.2) m, so 120 000 is the paper's full box
# (0.2 x 0.1 m) and 405 000 is 0.2 x 0.3375 m.
#
#   bench/dem_sizes.sh [--build DIR] [--sizes "15000 120000 405000"]
#                      [--liggghts-sizes "15000 120000"] [--settle 5000] [--steps 5000]
#
# Prints ns per particle-step for each engine and size, the ratio LIGGGHTS / ours, and each
# engine's cost per particle-step relative to its cost at the smallest size (1.00 = linear).
set -euo pipefail
shopt -s inherit_errexit
root=$(cd "$(dirname "$0")/.." && pwd)
build=build sizes="15000 120000 405000" lsizes="15000 120000" settle=5000 steps=5000
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=$2; shift 2 ;;
    --sizes) sizes=$2; shift 2 ;;
    --liggghts-sizes) lsizes=$2; shift 2 ;;
    --settle) settle=$2; shift 2 ;;
    --steps) steps=$2; shift 2 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "dem_sizes.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
bench="$build/bench/bench_dem"
[ -x "$bench" ] || { echo "dem_sizes.sh: build $bench first (scripts/build.sh)" >&2; exit 2; }
deck="$root/../shared/bench/liggghts/in.bed"
work=$(mktemp -d "${TMPDIR:-/tmp}/boycott_dem_sizes.XXXXXX")
trap 'rm -rf "$work"' EXIT

box() {  # prints "LX LZ" in m for N particles
  python3 -c "
n = $1
print(f'0.05 {0.05 * n / 15000:.6g}' if n <= 15000 else f'0.2 {0.05 * 0.05 * n / 15000 / 0.2:.6g}')"
}
ns_of() { sed -n 's/.*ns_per_particle_step=\([0-9.]*\).*/\1/p'; }

declare -A ours theirs
for n in $sizes; do
  read -r lx lz <<<"$(box "$n")"
  line=$(taskset -c 0 "$bench" "$settle" "$steps" "particles.count=$n" "domain.length_x=$lx" \
    "domain.height_z=$lz")
  echo "$line"
  ours[$n]=$(ns_of <<<"$line")
  if [[ " $lsizes " == *" $n "* ]]; then
    command -v liggghts >/dev/null || { echo "dem_sizes.sh: liggghts is not installed (apt-get install -y liggghts)" >&2; exit 2; }
    # The deck with its region and count scaled; everything else as it is.
    sed -e "s/block 0.0 0.05 0.0 0.006 0.0 0.05/block 0.0 $lx 0.0 0.006 0.0 $lz/" \
      -e "s/particles_in_region 15000/particles_in_region $n/" "$deck" > "$work/in.bed"
    grep -q "particles_in_region $n" "$work/in.bed" || { echo "dem_sizes.sh: the deck did not scale" >&2; exit 1; }
    (cd "$work" && taskset -c 0 liggghts -in in.bed -var drag 1 -var nsettle "$settle" -var nrun "$steps" \
      -log log.bed > screen.bed 2>&1)
    line=$(python3 - "$work/log.bed" <<'PY'
import re, sys
runs = [(float(t), int(s), int(n)) for t, s, n in
        re.findall(r"Loop time of ([0-9.eE+-]+) on \d+ procs for (\d+) steps with (\d+) atoms",
                   open(sys.argv[1]).read())]
t, steps, n = max(runs, key=lambda r: r[1])
print(f"liggghts: {n} particles, {steps} steps, {t:.2f} s, ns_per_particle_step={t / (steps * n) * 1e9:.1f}")
PY
)
    echo "$line"
    theirs[$n]=$(ns_of <<<"$line")
  fi
done

echo
echo "particles  boycott(ns)  vs-smallest  LIGGGHTS(ns)  vs-smallest  LIGGGHTS/boycott"
first=${sizes%% *}
for n in $sizes; do
  python3 -c "
o, o0 = ${ours[$n]}, ${ours[$first]}
t = '${theirs[$n]:-}'; t0 = '${theirs[$first]:-}'
ts = f'{float(t):12.1f}  {float(t) / float(t0):11.2f}  {float(t) / o:16.2f}' if t and t0 else f'{\"-\":>12s}  {\"-\":>11s}  {\"-\":>16s}'
print(f'{$n:9d}  {o:11.1f}  {o / o0:11.2f}  ' + ts)"
done
