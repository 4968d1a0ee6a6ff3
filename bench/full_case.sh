#!/usr/bin/env bash
# The full Table III base case at 65 deg (120 000 particles, 200 x 6 x 100 cells, the paper's
# settings) timed over an interval of the developed flow, on 1 and 2 MPI ranks.
#
#   bench/full_case.sh [--build DIR] [--previous DIR] [--from T] [--interval S] [--rounds R]
#                      [--ranks "1 2"] [--cache DIR] [--warmup DIR] [--set KEY=VALUE ...]
#
# --build DIR     the build to measure (default build); its driver/boycott is the binary.
# --previous DIR  a second build (an older binary) timed over the same interval, interleaved
#                 round by round with the first, since this machine drifts by 20-40 % from
#                 minute to minute; each binary starts from a checkpoint it wrote itself.
# --from T        start of the timed interval, s of simulated time (default 1.0).
# --interval S    its length, s (default 0.3).
# --rounds R      rounds of (each binary x each rank count) (default 1).
# --ranks LIST    rank counts (default "1 2").
# --cache DIR     where the checkpoints at T are kept (default ~/.cache/boycott-bench), one
#                 folder per binary's SHA-256: a checkpoint written by another binary is never
#                 reused. The first run of a binary writes it (2 ranks, tens of minutes at full
#                 size; an interrupted warm-up resumes).
# --warmup DIR    start every binary from this run folder's checkpoint at T instead of its own
#                 (a run of the same case that reached T, such as a warm-up in the cache): when
#                 a change moves round-off, the two warm-ups are two realisations of the flow
#                 and their costs differ with them; from one checkpoint the ratio is the code's.
# --set KEY=VALUE a case key changed for every run (another angle, a smaller box for a quick
#                 look); the warm-up folder's name holds them, so each variant has its own.
#
# For each run: wall time per simulated second, all-in ns per particle-step per core (wall time
# x ranks / (particles x DEM steps)), and each rank's phases from summary.json; then the parallel
# efficiency T1 / (N TN) and, with --previous, each pair's time ratio new / previous.
set -euo pipefail
shopt -s inherit_errexit
root=$(cd "$(dirname "$0")/.." && pwd)
extra=()
build=build previous="" from=1.0 interval=0.3 rounds=1 ranks="1 2" shared_warmup=""
cache=${XDG_CACHE_HOME:-$HOME/.cache}/boycott-bench
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=$2; shift 2 ;;
    --previous) previous=$2; shift 2 ;;
    --from) from=$2; shift 2 ;;
    --interval) interval=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    --ranks) ranks=$2; shift 2 ;;
    --cache) cache=$2; shift 2 ;;
    --warmup) shared_warmup=$2; shift 2 ;;
    --set) extra+=(--set "$2"); shift 2 ;;
    -h|--help) sed -n '2,29p' "$0"; exit 0 ;;
    *) echo "full_case.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
export OMPI_MCA_mpi_yield_when_idle=1
case_file="$root/studies/cases/inclined_settling_reduced.toml"
full=(--set domain.length_x=0.2 --set domain.height_z=0.1 --set 'domain.cells=[200,6,100]'
      --set gravity.angle_deg=65)
full+=("${extra[@]}")
variant=$(printf '%s\n' "${extra[@]}" | sha256sum | cut -c1-8)
to=$(python3 -c "print(round($from + $interval, 9))")
work=$(mktemp -d "${TMPDIR:-/tmp}/boycott_bench.XXXXXX")
trap 'rm -rf "$work"' EXIT

binary_of() {
  local b="$1/driver/boycott"
  [ -x "$b" ] || { echo "full_case.sh: no binary $b (build it first: scripts/build.sh)" >&2; exit 2; }
  (cd "$(dirname "$b")" && echo "$PWD/boycott")
}

# The checkpoint at T of one binary: its own warm-up run folder, resumed if interrupted.
warmup_of() {
  local bin=$1 sha dir
  sha=$(sha256sum "$bin" | cut -c1-16)
  dir="$cache/$sha/warmup_t${from}_$variant"
  if [ ! -f "$dir/summary.json" ]; then
    mkdir -p "$cache/$sha"
    echo "# warm-up of $bin ($sha) to t = $from s on 2 ranks, into $dir" >&2
    mpirun -n 2 "$bin" case run "$case_file" --out "$dir" "${full[@]}" --set "time.end=$from" \
      --set "time.average_from=$(python3 -c "print($from / 2)")" --set "time.checkpoint_every=0.1" \
      --progress-every 60 >&2
  fi
  echo "$dir"
}

new=$(binary_of "$build")
bins=("$new")
[ -n "$previous" ] && bins+=("$(binary_of "$previous")")
declare -A warm
if [ -n "$shared_warmup" ]; then
  [ -d "$shared_warmup/checkpoints" ] || { echo "full_case.sh: no checkpoints in '$shared_warmup'" >&2; exit 2; }
  shared_warmup=$(cd "$shared_warmup" && pwd)
fi
for b in "${bins[@]}"; do warm[$b]=${shared_warmup:-$(warmup_of "$b")}; done

results="$work/results.jsonl"
for r in $(seq 1 "$rounds"); do
  for n in $ranks; do
    for b in "${bins[@]}"; do
      tag=$([ "$b" = "$new" ] && echo new || echo previous)
      out="$work/${tag}_n${n}_r$r"
      t0=$(date +%s.%N)
      mpirun -n "$n" "$b" case run "$case_file" --from "${warm[$b]}" --at "$from" --out "$out" "${full[@]}" \
        --set "time.end=$to" --set "time.average_from=$from" --set "time.checkpoint_every=$interval" --quiet \
        2> "$out.stderr" || { cat "$out.stderr" >&2; exit 1; }
      t1=$(date +%s.%N)
      python3 - "$out/summary.json" "$tag" "$n" "$r" "$(python3 -c "print($t1 - $t0)")" "$interval" \
        >> "$results" <<'PY'
import json, os, sys
s = json.load(open(sys.argv[1]))
# This run's DEM step: the summary's step count runs from t = 0, through the warm-up's steps,
# which a --set time.dt_dem=... variant does not share.
dt_dem = json.load(open(os.path.join(os.path.dirname(sys.argv[1]), "params.json")))["time"]["dt_dem"]
print(json.dumps({"tag": sys.argv[2], "ranks": int(sys.argv[3]), "round": int(sys.argv[4]),
                  "wall_s": float(sys.argv[5]), "interval_s": float(sys.argv[6]),
                  "particles": s["particle_count"], "dt_dem_s": dt_dem, "per_rank": s["ranks"]["per_rank"],
                  "w_p": s.get("mean_settling_velocity_m_s"),
                  "rebuilds": s.get("neighbor_rebuilds_this_attempt")}))
PY
      tail -1 "$results" | python3 -c "
import json, sys
r = json.loads(sys.stdin.read())
print(f\"round {r['round']} {r['tag']:8s} {r['ranks']} rank(s): {r['wall_s'] / r['interval_s']:.0f} s per simulated s\", flush=True)"
    done
  done
done

python3 - "$results" "$from" "$to" <<'PY'
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
print(f"\nfull Table III case, 65 deg, interval t = {sys.argv[2]} .. {sys.argv[3]} s")
print("binary    ranks round  s/sim-s  ns/particle-step/core   phases per rank (s): "
      "fluid sample deposit contacts lists integr ghosts wait")
for r in rows:
    steps = r["interval_s"] / r["dt_dem_s"]
    ns = r["wall_s"] * r["ranks"] / (r["particles"] * steps) * 1e9
    r["ns"] = ns
    ph = " | ".join(
        " ".join(f"{p['seconds'].get(k, 0.0):.1f}" for k in
                 ("fluid", "coupling_sample", "coupling_deposit", "dem_contacts", "neighbor_search",
                  "integration", "ghost_refresh", "waiting")) for p in r["per_rank"])
    rb = f"   DEM steps per list rebuild {steps / r['rebuilds']:.1f}" if r.get("rebuilds") else ""
    print(f"{r['tag']:9s} {r['ranks']:5d} {r['round']:5d} {r['wall_s'] / r['interval_s']:8.0f} {ns:20.1f}   {ph}{rb}")
for tag in sorted({r["tag"] for r in rows}):
    by = {}
    for r in rows:
        if r["tag"] == tag: by.setdefault(r["round"], {})[r["ranks"]] = r["wall_s"]
    for n in sorted({k for v in by.values() for k in v if k > 1}):
        eff = [v[1] / (n * v[n]) for v in by.values() if 1 in v and n in v]
        if eff:
            print(f"{tag}: parallel efficiency T1/({n} T{n}) = " + ", ".join(f"{e:.2f}" for e in eff)
                  + f" (median {statistics.median(eff):.2f})")
pairs = {}
for r in rows: pairs.setdefault((r["round"], r["ranks"]), {})[r["tag"]] = r["wall_s"]
ratios = [(k, v["new"] / v["previous"]) for k, v in sorted(pairs.items()) if len(v) == 2]
for (rnd, n), q in ratios:
    print(f"round {rnd}, {n} rank(s): time new / previous = {q:.3f}")
if ratios:
    print(f"median time ratio new / previous = {statistics.median(q for _, q in ratios):.3f}")
PY
