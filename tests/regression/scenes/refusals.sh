#!/usr/bin/env bash
# What `case run` and `case check` refuse, and that a refused run writes nothing:
# non-finite values in any key, steps so small a run would never end or a fluid step never stop,
# repeated output times, case and study files that are FIFOs, devices or folders, sizes beyond this
# machine's memory (refused by case run, a warning of case check), a settling case without
# particles, an --out folder holding the user's own files, a folder another run holds, and a run
# folder whose params.json is damaged (unusable, exit 4, not bad input).
#   refusals.sh BOYCOTT_BIN CASE.toml
set -uo pipefail
bin=$1; case_file=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
fails=0
expect() {  # expected-exit description command...
  local want=$1 what=$2; shift 2
  "$@" > "$work/out.txt" 2>&1; local rc=$?
  if [ "$rc" -ne "$want" ]; then echo "FAIL $what: exit $rc, expected $want"; cat "$work/out.txt"; fails=$((fails + 1));
  else echo "ok   $what: exit $rc: $(grep -m1 -i 'error\|warning\|machine' "$work/out.txt" | cut -c1-110)"; fi
}
run() { "$bin" case run "$case_file" --out "$work/r" "$@"; }
for kv in time.end=inf time.dt_cfd=inf fluid.viscosity=inf domain.length_x=inf particles.density=-inf \
          particles.volume_fraction=nan; do
  expect 2 "--set $kv" run --set "$kv"
done
expect 2 "case check --set fluid.viscosity=inf" "$bin" case check "$case_file" --set fluid.viscosity=inf
expect 2 "time.dt_dem=1e-300 (never ends)" run --set time.dt_dem=1e-300 --set time.dt_cfd=1e-298
big=(--set 'domain.cells=[4096, 6, 4096]' --set domain.length_x=4.096 --set domain.height_z=4.096 --set particles.count=1000)
expect 2 "a 4096 x 6 x 4096 grid, case run" run "${big[@]}"
expect 0 "a 4096 x 6 x 4096 grid, case check warns" "$bin" case check "$case_file" "${big[@]}"
grep -q "on this machine" "$work/out.txt" || { echo "FAIL: no machine warning"; fails=$((fails + 1)); }
expect 2 "2e8 particles, case run" run --set particles.count=200000000 --set domain.length_x=2.0 --set domain.height_z=10.0
expect 2 "a settling case without particles" run --set particles.count=0
# A fluid step of 1e9 sub-steps: a stop inside it would drop more work than any case needs.
expect 2 "time.dt_dem=1e-12 (1e9 sub-steps per fluid step)" run --set time.dt_dem=1e-12
expect 2 "case check --set time.dt_dem=1e-12" "$bin" case check "$case_file" --set time.dt_dem=1e-12
expect 2 "a snapshot time listed twice" run --set 'output.snapshot_times=[0.01, 0.02, 0.01]'
expect 2 "one cell across the gap, case check" "$bin" case check "$case_file" --set 'domain.cells=[20, 1, 20]'
expect 2 "one cell across the gap, case run" run --set 'domain.cells=[20, 1, 20]'
# Files that are not files: a FIFO would block a reader, a link to /dev/zero would never end.
mkfifo "$work/fifo.toml"; ln -s /dev/zero "$work/zero.toml"; mkdir "$work/dir.toml"
for f in fifo.toml zero.toml dir.toml; do
  expect 2 "case check of $f" timeout 60 "$bin" case check "$work/$f"
  expect 2 "case run of $f" timeout 60 "$bin" case run "$work/$f" --out "$work/r"
  expect 2 "study plan of $f" timeout 60 "$bin" study plan "$work/$f"
done
[ ! -e "$work/r" ] || { echo "FAIL: a refused run wrote $work/r"; ls -la "$work/r"; fails=$((fails + 1)); }
# An --out folder with the user's own files: refused, untouched, nothing written.
mkdir -p "$work/mine"
for f in summary.json timeseries.csv pdf_y.csv; do echo "user's own $f" > "$work/mine/$f"; done
( cd "$work/mine" && sha256sum * > ../mine.sha )
expect 4 "--out a folder of the user's" "$bin" case run "$case_file" --out "$work/mine" --set time.end=0.02 --set time.average_from=0.01
( cd "$work/mine" && sha256sum -c --quiet ../mine.sha ) || { echo "FAIL: the user's files changed"; fails=$((fails + 1)); }
[ "$(ls "$work/mine" | wc -l)" -eq 3 ] || { echo "FAIL: files written into the user's folder"; ls "$work/mine"; fails=$((fails + 1)); }
# A run folder whose params.json was damaged (a wrong type): unusable (4), not bad input (2).
"$bin" case run "$case_file" --out "$work/ok" --set time.end=0.02 --set time.average_from=0.01 > /dev/null 2>&1
python3 - "$work/ok/params.json" <<'PY'
import json, sys
p = json.load(open(sys.argv[1])); p["fluid"]["viscosity"] = "thick"; json.dump(p, open(sys.argv[1], "w"))
PY
expect 4 "a run folder with a mistyped params.json" "$bin" case run "$case_file" --out "$work/ok" --set time.end=0.02 --set time.average_from=0.01
# An --out where no folder can be made, a --db that is a folder: a sentence and exit 2.
expect 2 "--out under /proc" "$bin" case run "$case_file" --out /proc/boycott_x --set time.end=0.02 --set time.average_from=0.01
grep -q "cannot make the run folder there" "$work/out.txt" || { echo "FAIL: no sentence for --out"; cat "$work/out.txt"; fails=$((fails + 1)); }
mkdir -p "$work/dbdir"
expect 2 "--db a folder" "$bin" query curve --db "$work/dbdir" --study x
grep -q "is a folder: name the database file in it" "$work/out.txt" || { echo "FAIL: no sentence for --db"; cat "$work/out.txt"; fails=$((fails + 1)); }
# Two `case run` into one folder: the second is refused at once (4) naming the holder's pid, and
# writes nothing; the first runs on (stopped here by SIGTERM after its first checkpoint, exit 75).
"$bin" case run "$case_file" --out "$work/busy" --set time.end=5 --set time.average_from=1 \
  --set time.checkpoint_every=0.01 --quiet > /dev/null 2>&1 &
first=$!
until compgen -G "$work/busy/checkpoints/ckpt_*.h5" > /dev/null; do
  kill -0 "$first" 2> /dev/null || { echo "FAIL: the first run ended before its first checkpoint"; exit 1; }
  sleep 0.05
done
expect 4 "a second case run into a running folder" "$bin" case run "$case_file" --out "$work/busy" --set time.end=5 --set time.average_from=1
grep -q "is in use: process $first holds its .lock" "$work/out.txt" || { echo "FAIL: the holder is not named"; cat "$work/out.txt"; fails=$((fails + 1)); }
kill -TERM "$first"; wait "$first"; rc=$?
[ "$rc" -eq 75 ] || { echo "FAIL: the first run, stopped, exit $rc (expected 75)"; fails=$((fails + 1)); }
grep -q '"interrupted"' "$work/busy/summary.json" || { echo "FAIL: the first run's summary"; fails=$((fails + 1)); }
[ "$fails" -eq 0 ] && echo "[ report ] every refusal as expected" || exit 1
