#!/usr/bin/env bash
# A scene stopped by SIGTERM ends as every scene's stop does: exit 75 and a summary marked
# interrupted, so that a study runs it again without counting a failure. Then:
# * single_particle (the coupled scenes' time loop) has checkpointed: a rerun in the same folder
#   resumes, and its time series and terminal velocity equal, bit for bit, those of a run straight
#   to the same end;
# * ergun and dem_only keep no checkpoint and say that a rerun starts over; dem_only run again
#   (to a little past where it stopped: an end below that is refused) completes. ergun's rerun,
#   its 400 points again, is left out: the gradients are part of its case, so no shorter one exists.
#   stopped_scene.sh BOYCOTT_BIN SCENE [CASE.toml: single_particle's]
set -uo pipefail
bin=$1; scene=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
sets=() first=()
case "$scene" in
  single_particle)
    cp "$3" "$work/case.toml"
    sets=(--set time.average_from=0.01 --set time.checkpoint_every=0.005) first=(--set time.end=30) ;;
  # Many gradients, each run to a steady state: long enough to be stopped after its first point.
  ergun)
    body=$'[particles]\ndiameter = 1.0e-3\n[domain]\nlength_x = 0.006\nwidth_y = 0.006\nheight_z = 0.006\ncells = [6, 6, 6]\n[ergun]\npressure_gradients = ['
    body+=$(python3 -c 'print(", ".join(f"{100 * 1.05**k:.6g}" for k in range(400)))')$']' ;;
  dem_only)
    body=$'[domain]\nlength_x = 0.01\nheight_z = 0.01\n[time]\nend = 30.0\naverage_from = 0.01' ;;
  *) fail "unknown scene $scene" ;;
esac
[ -f "$work/case.toml" ] || printf 'scene = "%s"\n%s\n' "$scene" "$body" > "$work/case.toml"
dir=$work/run
"$bin" case run "$work/case.toml" --out "$dir" "${first[@]}" "${sets[@]}" > /dev/null 2> "$work/err.txt" &
pid=$!
# Two rows of the time series: the run is under way.
until [ "$(wc -l < "$dir/timeseries.csv" 2> /dev/null || echo 0)" -ge 3 ]; do
  kill -0 "$pid" 2> /dev/null || fail "the run ended before it was stopped: $(cat "$work/err.txt")"
  sleep 0.05
done
kill -TERM "$pid"
wait "$pid"; rc=$?
[ "$rc" -eq 75 ] || fail "stopped run exit $rc (expected 75): $(cat "$work/err.txt")"
grep -q '"status": "interrupted"' "$dir/summary.json" || fail "summary not interrupted: $(cat "$dir/summary.json")"
# A little past where it stopped.
end=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["simulated_time_s"] + 0.05)' "$dir/summary.json")
rerun() {  # rerun OUT_DIR: the same case to $end
  "$bin" case run "$work/case.toml" --out "$1" --set time.end="$end" "${sets[@]}" --quiet > /dev/null 2> "$work/err2.txt" ||
    fail "the run to $end s in $1 failed: $(cat "$work/err2.txt")"
}
case "$scene" in
  single_particle)
    ls "$dir"/checkpoints/*.h5 > /dev/null 2>&1 || fail "no checkpoint after the stop"
    rerun "$dir"
    rerun "$work/ref"
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
    ;;
  *)
    grep -q 'a rerun starts over' "$work/err.txt" || fail "no word that a rerun starts over: $(cat "$work/err.txt")"
    if [ "$scene" = dem_only ]; then
      rerun "$dir"
      grep -q '"status": "completed"' "$dir/summary.json" || fail "the rerun did not complete: $(cat "$dir/summary.json")"
    fi
    echo "[ report ] $scene stopped: exit 75, interrupted, a rerun starts over" ;;
esac
