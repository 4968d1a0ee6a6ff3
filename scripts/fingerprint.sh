#!/usr/bin/env bash
# Prints a checksum of the time series of short runs of every scene, for refactors that must keep
# the bits (a change in the order of floating-point operations shows up here). Compare the output
# of two builds on the same machine (-march=native makes the bits machine-specific):
#   scripts/fingerprint.sh [BOYCOTT_BIN] > before.txt   ...   diff before.txt after.txt
# ctest Fingerprint.SummariesMatchTheCommittedReference compares its summary values with
# tests/data/fingerprint_reference.txt (tests/regression/fingerprint_compare.py says within what).
# BOYCOTT_FINGERPRINT_VISCOSITY_FACTOR=F runs every case with its fluid viscosity times F: F one
# ulp from 1 shows how far round-off grows in these runs, F = 1.001 is a planted change.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$root/build/driver/boycott}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
c=$root/studies/cases
# The cases' own viscosities (channel_flow.toml sets 0.1 Pa s; the others run at the default).
visc() {
  [ -n "${BOYCOTT_FINGERPRINT_VISCOSITY_FACTOR:-}" ] || return 0
  echo "--set fluid.viscosity=$(python3 -c "print(repr($1 * $BOYCOTT_FINGERPRINT_VISCOSITY_FACTOR))")"
}
run() {  # name, ranks, case file, --set arguments...
  local name=$1 ranks=$2 file=$3; shift 3
  local launch=("$bin")
  [ "$ranks" -gt 1 ] && launch=(mpirun -n "$ranks" "$bin")
  "${launch[@]}" case run "$file" --out "$work/$name" "$@" > /dev/null 2> "$work/$name.err" ||
    { echo "$name: failed"; cat "$work/$name.err"; return; }
  for f in timeseries.csv profiles.csv; do
    [ -f "$work/$name/$f" ] && echo "$name $f $(sha256sum < "$work/$name/$f" | cut -c1-16)"
  done
  python3 - "$work/$name/summary.json" "$name" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
keys = [k for k in ("mean_settling_velocity_m_s", "settling_velocity_stderr_m_s", "max_rel_error_vs_analytic",
                    "terminal_velocity_m_s", "max_rel_error_f_star", "mean_velocity_m_s") if s.get(k) is not None]
print(sys.argv[2], "summary", " ".join(f"{k}={s[k]!r}" for k in keys))
PY
}
run demo50 1 "$c/inclined_settling_smoke.toml" $(visc 1e-3) --set gravity.angle_deg=50 --set time.end=0.3 --set time.average_from=0.1
run demo90_piso 1 "$c/inclined_settling_smoke.toml" $(visc 1e-3) --set gravity.angle_deg=90 --set time.end=0.2 \
  --set time.average_from=0.1 --set numerics.pressure_velocity_coupling=\"piso\"
run sediment 1 "$c/sediment_transport.toml" $(visc 1e-3) --set time.end=0.05 --set time.average_from=0.02
run ergun 1 "$c/ergun.toml" $(visc 1e-3)
run single 1 "$c/single_particle.toml" $(visc 1e-3) --set time.end=0.1 --set time.average_from=0.05
run channel 1 "$c/channel_flow.toml" $(visc 0.1) --set time.end=0.2
run channel_2ranks 2 "$c/channel_flow.toml" $(visc 0.1) --set time.end=0.2
run dem_only 1 "$c/dem_only.toml" $(visc 1e-3) --set time.end=0.05 --set time.average_from=0.02
