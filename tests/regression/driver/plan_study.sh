#!/usr/bin/env bash
# `study plan`: before any run it lists the cases as pending and creates no database; after the
# study ran, each finished case's cost (its CPU time) predicted by the model fitted to the other
# five (leave one out) is within 30 % of its measured cost; bad --jobs exits 2; `study run` prints
# the plan line before it starts and writes the tree of readable names beside the run folders.
#   plan_study.sh BOYCOTT_BIN STUDY.toml
set -euo pipefail
bin=$1; study=$2
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
db=$work/plan.db
"$bin" study plan "$study" --db "$db" --jobs 2 > "$work/plan0.txt"
grep -q '6 cases, 6 to run' "$work/plan0.txt" || { cat "$work/plan0.txt"; exit 1; }
grep -q 'cost model inclined_settling: default' "$work/plan0.txt" || { cat "$work/plan0.txt"; exit 1; }
[ ! -e "$db" ] || { echo "study plan created a database"; exit 1; }
if "$bin" study plan "$study" --jobs 0 > /dev/null 2>&1; then echo "--jobs 0 accepted"; exit 1; else rc=$?; fi
[ "$rc" -eq 2 ] || { echo "--jobs 0 exited $rc, not 2"; exit 1; }
# One case at a time, so that the measured costs are not two runs sharing the cores; a tiny run
# beforehand reads the binary, PETSc and MPI from disk, so that the first case does not pay for it
# (it cost up to 1 CPU-s more than its twin otherwise).
smoke=$(dirname "$study")/../../../studies/cases/inclined_settling_smoke.toml
"$bin" case run "$smoke" --out "$work/warm" --set time.end=0.002 --set time.average_from=0.001 --quiet \
  > /dev/null 2>&1
"$bin" study run "$study" --db "$db" --jobs 1 > /dev/null 2> "$work/run_err.txt"
grep -q '^plan: 6 cases to run, estimated ' "$work/run_err.txt" || { cat "$work/run_err.txt"; exit 1; }
# Beside the hash folders, a tree of readable names linking to them (one component per varied key).
leaf="$db.names/plan_check/base/particles.volume_fraction=0.03/domain.cells=20,6,40/domain.height_z=0.04"
[ -L "$leaf" ] && [ -f "$leaf/summary.json" ] || { echo "no run-tree link $leaf:"; find "$db.names"; exit 1; }
[ "$(find "$db.names" -type l | wc -l)" -eq 6 ] || { echo "expected 6 links:"; find "$db.names"; exit 1; }
"$bin" study plan "$study" --db "$db" --check-model --format json > "$work/plan.json"
python3 - "$work/plan.json" <<'PY'
import json, sys
p = json.load(open(sys.argv[1]))
assert p["remaining_cases"] == 0 and len(p["cases"]) == 6, p
worst = 0.0
for c in p["cases"]:
    assert c["state"] == "done" and c["cost_basis"] == "fit to 6 runs", c
    rel = c["predicted_by_others_core_s"] / c["measured_core_s"] - 1
    print(f"[ report ] {c['swept']}: measured {c['measured_core_s']:.2f} core-s, "
          f"from the other five {c['predicted_by_others_core_s']:.2f} ({100 * rel:+.0f} %)")
    worst = max(worst, abs(rel))
assert worst <= 0.30, f"leave-one-out error {worst:.2f} > 0.30"
print(f"[ report ] largest leave-one-out error {100 * worst:.0f} %")
PY
