#!/usr/bin/env bash
# Runs a small real study (dem_only scene) through `boycott study run` and checks that
# `boycott query curve` returns, per angle, exactly the value and error of each case's summary.json
# and the ratio to 90 deg with its propagated error.
set -euo pipefail
bin=$1; study=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$bin" study run "$study" --db "$work/s.sqlite" --jobs 2 > "$work/out.txt"
"$bin" query curve --db "$work/s.sqlite" --study dem_angles --format json > "$work/curve.json"
python3 - "$work" <<'PY'
import json, math, sys, pathlib
work = pathlib.Path(sys.argv[1])
curve = json.load(open(work / "curve.json"))
assert len(curve) == 3, curve
ref = {}
for row in curve:
    s = json.load(open(work / "s.sqlite.runs" / row["case_id"] / "summary.json"))
    assert s["status"] == "completed"
    assert row["mean_settling_velocity_m_s"] == s["mean_settling_velocity_m_s"], (row, s)
    assert row["stderr_m_s"] == s["settling_velocity_stderr_m_s"]
    ref[row["angle_deg"]] = s
w90 = ref[90.0]["mean_settling_velocity_m_s"]; e90 = ref[90.0]["settling_velocity_stderr_m_s"]
for row in curve:
    w = row["mean_settling_velocity_m_s"]; e = row["stderr_m_s"]
    r = w / w90
    assert abs(row["r_acc"] - r) <= 1e-12 * abs(r)
    if row["angle_deg"] != 90.0:
        err = abs(r) * math.hypot(e / w, e90 / w90)
        assert abs(row["r_acc_err"] - err) <= 1e-9 * err, (row, err)
# Dry settling with Stokes drag: steeper channels settle faster (gravity along z grows).
ws = [row["mean_settling_velocity_m_s"] for row in sorted(curve, key=lambda r: r["angle_deg"])]
assert ws[0] > ws[1] > ws[2], ws
print("curve matches the case summaries:", ws)
PY
