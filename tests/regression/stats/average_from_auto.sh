#!/usr/bin/env bash
# time.average_from = "auto" on a real coupled case through the study driver: the window starts
# where the run's start-up transient was detected to end (average_from_s = transient_end_s, in
# (0, end)); <<w_p>> is the mean of the per-step samples after it (every step written out); the
# database row records that window; `case summarize` recomputes the same window and numbers.
#   average_from_auto.sh BOYCOTT_BIN CASE.toml
set -euo pipefail
bin=$1; case_file=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
{ echo 'name = "auto_window"'; echo '[base]';
  sed -e 's/^\[\(.*\)\]$/[base.\1]/' -e '/^end = /d' -e '/^average_from = /d' "$case_file" | grep -v '^#';
  printf '[matrix]\n"time.end" = [3.0]\n"time.average_from" = ["auto"]\n'; } > "$work/study.toml"
"$bin" study run "$work/study.toml" --db "$work/r.sqlite" --quiet > "$work/run.txt" 2>&1 || { cat "$work/study.toml" "$work/run.txt"; exit 1; }
run=$(ls -d "$work"/r.sqlite.runs/*/)
cp "$run/summary.json" "$work/first.json"
"$bin" case summarize "$run" --db "$work/r.sqlite" > /dev/null
python3 - "$work" "$run" <<'PY'
import csv, json, sqlite3, sys, pathlib
work, run = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
s = json.load(open(work / "first.json"))
again = json.load(open(run / "summary.json"))
assert json.load(open(run / "params.json"))["time"]["average_from"] == "auto"
a, e = s["average_from_s"], s["transient_end_s"]
print(f"[ report ] auto window: from {a:.4g} s (transient end {e:.4g} s) to {s['simulated_time_s']:.4g} s, "
      f"{s['samples_averaged']} of {s['cfd_steps']} steps, <<w_p>> {s['mean_settling_velocity_m_s']:.6g} m/s")
assert a == e and 0.0 < a < 3.0, (a, e)
assert s["pdfs_and_fluid_means_from_s"] == 0.0
rows = [r for r in csv.DictReader(open(run / "timeseries.csv")) if float(r["time_s"]) > a + 1e-12]
assert len(rows) == s["samples_averaged"] < s["cfd_steps"], (len(rows), s["samples_averaged"], s["cfd_steps"])
mean = sum(float(r["mean_wp_m_s"]) for r in rows) / len(rows)
assert abs(mean / s["mean_settling_velocity_m_s"] - 1) < 1e-9, (mean, s["mean_settling_velocity_m_s"])
for k in ("average_from_s", "mean_settling_velocity_m_s", "settling_velocity_stderr_m_s", "samples_averaged"):
    assert again[k] == s[k], (k, again[k], s[k])
db = sqlite3.connect(work / "r.sqlite")
(row_from, row_mean), = db.execute("SELECT average_from_s, mean_settling_velocity_m_s FROM results")
assert row_from == a and row_mean == s["mean_settling_velocity_m_s"], (row_from, row_mean)
PY
