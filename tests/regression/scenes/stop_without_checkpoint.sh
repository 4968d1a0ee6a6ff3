#!/usr/bin/env bash
# A scene that writes no checkpoint (ergun, dem_only) stopped by SIGTERM ends as every scene's stop
# does: exit 75 and a summary marked interrupted (a study runs it again without counting a
# failure), saying that a rerun starts over; dem_only run again in the same folder (to a little
# past where it stopped: an end below that is refused) starts over and completes. (ergun's rerun,
# its 400 points again, is left out: the gradients are part of its case, so no shorter rerun exists.)
#   stop_without_checkpoint.sh BOYCOTT_BIN SCENE
set -uo pipefail
bin=$1; scene=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
case "$scene" in
  # Many gradients, each run to a steady state: long enough to be stopped after its first point.
  ergun)
    body=$'[particles]\ndiameter = 1.0e-3\n[domain]\nlength_x = 0.006\nwidth_y = 0.006\nheight_z = 0.006\ncells = [6, 6, 6]\n[ergun]\npressure_gradients = ['
    body+=$(python3 -c 'print(", ".join(f"{100 * 1.05**k:.6g}" for k in range(400)))')$']'
    ;;
  dem_only)
    body=$'[domain]\nlength_x = 0.01\nheight_z = 0.01\n[time]\nend = 30.0\naverage_from = 0.01'
    ;;
  *) fail "unknown scene $scene" ;;
esac
printf 'scene = "%s"\n%s\n' "$scene" "$body" > "$work/case.toml"
dir=$work/run
"$bin" case run "$work/case.toml" --out "$dir" > /dev/null 2> "$work/err.txt" &
pid=$!
# A row of the time series: the run is under way.
until [ "$(wc -l < "$dir/timeseries.csv" 2> /dev/null || echo 0)" -ge 2 ]; do
  kill -0 "$pid" 2> /dev/null || fail "the run ended before it was stopped: $(cat "$work/err.txt")"
  sleep 0.05
done
kill -TERM "$pid"
wait "$pid"; rc=$?
[ "$rc" -eq 75 ] || fail "stopped run exit $rc (expected 75): $(cat "$work/err.txt")"
grep -q '"status": "interrupted"' "$dir/summary.json" || fail "summary not interrupted: $(cat "$dir/summary.json")"
grep -q 'a rerun starts over' "$work/err.txt" || fail "no word that a rerun starts over: $(cat "$work/err.txt")"
if [ "$scene" = dem_only ]; then
  end=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["simulated_time_s"] + 0.02)' "$dir/summary.json")
  "$bin" case run "$work/case.toml" --out "$dir" --set time.end="$end" --quiet > /dev/null 2> "$work/err2.txt" ||
    fail "the rerun failed: $(cat "$work/err2.txt")"
  grep -q '"status": "completed"' "$dir/summary.json" || fail "the rerun did not complete: $(cat "$dir/summary.json")"
fi
echo "[ report ] $scene stopped: exit 75, interrupted, a rerun starts over"
