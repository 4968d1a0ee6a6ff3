#!/usr/bin/env bash
# single_particle runs the coupled scenes' time loop: a stop (SIGTERM) checkpoints, exits 75 with
# a summary marked interrupted, and a rerun in the same folder resumes from the checkpoint; the
# resumed run's time series and terminal velocity equal, bit for bit, those of a run straight to
# the same end.
#   single_particle_stop.sh BOYCOTT_BIN CASE.toml
set -uo pipefail
bin=$1; case_file=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
dir=$work/run
sets=(--set time.average_from=0.01 --set time.checkpoint_every=0.005)
"$bin" case run "$case_file" --out "$dir" --set time.end=30 "${sets[@]}" > /dev/null 2> "$work/err.txt" &
pid=$!
# Two rows of the time series: the run is stepping.
until [ "$(wc -l < "$dir/timeseries.csv" 2> /dev/null || echo 0)" -ge 3 ]; do
  kill -0 "$pid" 2> /dev/null || fail "the run ended before it was stopped: $(cat "$work/err.txt")"
  sleep 0.05
done
kill -TERM "$pid"
wait "$pid"; rc=$?
[ "$rc" -eq 75 ] || fail "stopped run exit $rc (expected 75): $(cat "$work/err.txt")"
grep -q '"status": "interrupted"' "$dir/summary.json" || fail "summary not interrupted: $(cat "$dir/summary.json")"
ls "$dir"/checkpoints/*.h5 > /dev/null 2>&1 || fail "no checkpoint after the stop"
# Resume to a little past where it stopped; then a run straight to the same end.
end=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["simulated_time_s"] + 0.05)' "$dir/summary.json")
"$bin" case run "$case_file" --out "$dir" --set time.end="$end" "${sets[@]}" --quiet \
  > /dev/null 2> "$work/err2.txt" || fail "the rerun failed: $(cat "$work/err2.txt")"
"$bin" case run "$case_file" --out "$work/ref" --set time.end="$end" "${sets[@]}" --quiet \
  > /dev/null 2> "$work/err3.txt" || fail "the straight run failed: $(cat "$work/err3.txt")"
python3 - "$dir" "$work/ref" <<'PY' || exit 1
import json, sys, pathlib
run, ref = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
a = json.load(open(run / "summary.json")); b = json.load(open(ref / "summary.json"))
assert a["status"] == "completed", a["status"]
assert a["resumed_from_checkpoint"] is True, "the rerun did not resume"
for k in ("terminal_velocity_m_s", "settling_velocity_stderr_m_s", "initial_acceleration_z_m_s2",
          "simulated_time_s", "particle_steps"):
    assert a[k] == b[k], (k, a[k], b[k])
assert (run / "timeseries.csv").read_text() == (ref / "timeseries.csv").read_text(), "time series differ"
print(f"[ report ] stopped at exit 75, resumed from its checkpoint to t = {a['simulated_time_s']:.4g} s: "
      "time series and terminal velocity identical to a run straight to that end")
PY
