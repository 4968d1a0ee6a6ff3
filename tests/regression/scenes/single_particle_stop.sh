#!/usr/bin/env bash
# single_particle writes no checkpoint, but a stop (SIGTERM) ends it as every scene's does: exit
# 75 and a summary marked interrupted, so that a study runs it again (a failure would be counted
# against its retries); run again in the same folder it starts over and completes.
#   single_particle_stop.sh BOYCOTT_BIN CASE.toml
set -uo pipefail
bin=$1; case_file=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
dir=$work/run
"$bin" case run "$case_file" --out "$dir" --set time.end=30 --set time.average_from=0.01 > /dev/null 2> "$work/err.txt" &
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
grep -q 'a rerun starts over' "$work/err.txt" || fail "no word that it starts over: $(cat "$work/err.txt")"
# Run again to a little past where it stopped (an end below that is refused): it starts over.
end=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["simulated_time_s"] + 0.02)' "$dir/summary.json")
"$bin" case run "$case_file" --out "$dir" --set time.end="$end" --set time.average_from=0.01 --quiet \
  > /dev/null 2> "$work/err2.txt" || fail "the rerun failed: $(cat "$work/err2.txt")"
grep -q '"status": "completed"' "$dir/summary.json" || fail "the rerun did not complete: $(cat "$dir/summary.json")"
echo "[ report ] stopped: exit 75, interrupted; rerun in the same folder completed"
