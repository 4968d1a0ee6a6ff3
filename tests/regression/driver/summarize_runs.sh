#!/usr/bin/env bash
# `boycott case summarize`: a finished run of a real study, its summary made to look like an older
# build's (the covering error and the transient keys removed, the plain error doubled), is
# recomputed from its checkpoint: summary.json and the database row get this build's statistics
# back, equal to what the run itself reported; the replaced summary is kept; a second pass changes
# nothing; a folder that is no finished run is refused (exit 2) before anything is written.
set -euo pipefail
bin=$1
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cat > "$work/s.toml" <<'TOML'
name = "summ"
[base]
scene = "inclined_settling"
[base.particles]
volume_fraction = 0.113
[base.domain]
length_x = 0.02
width_y = 0.006
height_z = 0.02
cells = [20, 6, 20]
[base.time]
end = 0.5
average_from = 0.25
[matrix]
"gravity.angle_deg" = [60]
TOML
"$bin" study run "$work/s.toml" --db "$work/s.db" --quiet > /dev/null
run=$(ls -d "$work"/s.db.runs/*/)
cp "$run/summary.json" "$work/fresh.json"
python3 - "$run/summary.json" <<'PY'
import json, sys
p = sys.argv[1]; j = json.load(open(p))
for k in ("settling_velocity_error_m_s", "settling_velocity_error_dof", "transient_end_s", "average_from_s",
          "settling_velocity_time_weighted_m_s"):
    j.pop(k, None)
j["settling_velocity_stderr_m_s"] = 2 * (j["settling_velocity_stderr_m_s"] or 1e-3)
j["warnings"] = ["the averaging window (old text)", "kept: a warning of another kind"]
json.dump(j, open(p, "w"))
PY
# A folder that is no finished run, listed first: refused, nothing written (the old summary stays).
mkdir "$work/empty"
rc=0; "$bin" case summarize "$work/empty" "$run" --db "$work/s.db" > "$work/out.txt" 2>&1 || rc=$?
[ "$rc" = 2 ] || { echo "summarize of a folder without a run: exit $rc"; cat "$work/out.txt"; exit 1; }
grep -q "no summary.json" "$work/out.txt" || { cat "$work/out.txt"; exit 1; }
[ ! -e "$run/summary.previous.json" ] || { echo "a refused summarize wrote"; exit 1; }
"$bin" case summarize "$run" --db "$work/s.db" > "$work/out.txt" 2> "$work/err.txt"
grep -q "database row updated" "$work/out.txt" || { cat "$work/out.txt" "$work/err.txt"; exit 1; }
"$bin" case summarize "$run" --db "$work/s.db" > "$work/out2.txt" 2>> "$work/err.txt"
python3 - "$work" "$run" <<'PY'
import json, sqlite3, sys, pathlib
work, run = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
fresh = json.load(open(work / "fresh.json"))
new = json.load(open(run / "summary.json"))
prev = json.load(open(run / "summary.previous.json"))
keys = ("mean_settling_velocity_m_s", "settling_velocity_stderr_m_s", "settling_velocity_error_m_s",
        "settling_velocity_error_dof", "transient_end_s", "average_from_s", "settling_velocity_time_weighted_m_s",
        "settling_velocity_window_correlation_times")
for k in keys:
    assert new.get(k) == fresh.get(k), (k, new.get(k), fresh.get(k))
assert "kept: a warning of another kind" in new["warnings"], new["warnings"]
assert "the averaging window (old text)" not in new["warnings"], new["warnings"]
# The second pass kept the first pass's summary as the previous one: nothing changed.
assert {k: prev.get(k) for k in keys} == {k: new.get(k) for k in keys}
db = sqlite3.connect(work / "s.db")
err, summary = db.execute("SELECT settling_velocity_stderr_m_s, summary_json FROM results").fetchone()
assert err == fresh["settling_velocity_stderr_m_s"], (err, fresh["settling_velocity_stderr_m_s"])
assert json.loads(summary)["settling_velocity_error_dof"] == fresh["settling_velocity_error_dof"]
print(f"[ report ] recomputed: error {new['settling_velocity_error_m_s']}, dof {new['settling_velocity_error_dof']:.3g}, "
      f"transient ends at {new['transient_end_s']:.3g} s")
PY
