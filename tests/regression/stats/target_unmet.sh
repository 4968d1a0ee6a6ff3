#!/usr/bin/env bash
# time.target_rel_error on a real coupled case, the quick half (the loose target's early stop and
# resume run ~100 simulated s: target_rel_error.sh, label long): a target the run cannot meet by
# time.end ends "completed" at time.end with target_met false, the target and the relative error
# it reached in summary.json, and the same case id as without a target.
#   target_unmet.sh BOYCOTT_BIN CASE.toml TARGET END_S
set -euo pipefail
bin=$1; case_file=$2; target=$3; end=$4
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
sed "s/^end = .*/end = $end/" "$case_file" > "$work/plain.toml"
sed "s/^\[time\]/[time]\ntarget_rel_error = $target/" "$work/plain.toml" > "$work/target.toml"
"$bin" case run "$work/target.toml" --out "$work/run" > "$work/run.txt" 2>&1 || { cat "$work/run.txt"; exit 1; }
"$bin" case check "$work/plain.toml" > "$work/plain_check.txt"
python3 - "$work" "$target" "$end" <<'PY'
import json, sys, pathlib
work = pathlib.Path(sys.argv[1]); target, end = float(sys.argv[2]), float(sys.argv[3])
s = json.load(open(work / "run" / "summary.json"))
print(f"[ report ] target {target:g}: {s['status']} at t = {s['simulated_time_s']:.4g} s of {end:g}, "
      f"relative error {s['settling_velocity_rel_stderr']}, target_met {s['target_met']}")
assert s["status"] == "completed", s["status"]
assert s["target_met"] is False and s["target_rel_error"] == target
assert s["simulated_time_s"] >= end - 1e-9, s["simulated_time_s"]
rel = s["settling_velocity_rel_stderr"]
assert rel is None or rel >= target, rel
plain_id = (work / "plain_check.txt").read_text().split()[1]  # "case ID (scene ...): valid"
assert s["case_id"] == plain_id, (s["case_id"], plain_id)
PY
