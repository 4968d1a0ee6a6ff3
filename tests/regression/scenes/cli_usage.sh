#!/usr/bin/env bash
# The command line as a user meets it: every usage error exits 2 and names the word it did not
# understand (an unknown option before `--` included: it is not handed on to PETSc); PETSc options
# after `--` that nothing used are reported; a run without a terminal prints a progress line every
# --progress-every seconds (here: every step) and a last line with its outcome; summary.json records the build.
#   cli_usage.sh BOYCOTT_BIN CASE.toml
set -uo pipefail
bin=$1; case_file=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
expect_usage() {  # expect_usage WORD ARGS...: exit 2, the word named on stderr, no run folder
  local word=$1; shift
  "$bin" "$@" > "$work/out.txt" 2> "$work/err.txt"; local rc=$?
  [ "$rc" -eq 2 ] || fail "'$*' exited $rc, not 2: $(cat "$work/err.txt")"
  grep -qF -- "$word" "$work/err.txt" || fail "'$*' does not name '$word': $(cat "$work/err.txt")"
  [ ! -e "$work/never" ] || fail "'$*' wrote a run folder"
}
expect_usage frobnicate frobnicate
expect_usage frob case frob
expect_usage --bogus case run "$case_file" --out "$work/never" --bogus
expect_usage --sideways case run "$case_file" --out "$work/never" --at 0.1 --sideways
expect_usage nofile.toml case run "$work/nofile.toml" --out "$work/never"
# Every listing command takes the same --format choices and refuses others alike.
for cmd in "query curve --study s" "query validation" "query work-precision --study s" "query cases"; do
  # shellcheck disable=SC2086
  expect_usage xml $cmd --db "$work/none.db" --format xml
done
expect_usage xml study status "$(dirname "$case_file")/../demo.toml" --db "$work/none.db" --format xml
expect_usage xml study plan "$(dirname "$case_file")/../demo.toml" --format xml
expect_usage xml case keys --format xml
"$bin" --help > /dev/null
# (Through files: with pipefail, grep -q closing the pipe early would fail the writer.)
"$bin" query cases --help > "$work/help.txt"
grep -q '{table,csv,json}' "$work/help.txt" || fail "query cases --help does not list the formats"
# A database with the demo's 12 cases done (by the test double of the solver, in a second).
fake="python3 $(cd "$(dirname "$0")/../driver" && pwd)/fake_solver.py"
"$bin" study run "$(dirname "$case_file")/../demo.toml" --db "$work/empty.db" --solver-command "$fake" --jobs 2 --quiet \
  > "$work/run.txt" 2>&1 || fail "the study run of the test double failed: $(cat "$work/run.txt")"
"$bin" study status "$(dirname "$case_file")/../demo.toml" --db "$work/empty.db" --format json > "$work/status.json" ||
  fail "study status --format json failed: $(cat "$work/status.json")"
python3 -c "import json,sys; j=json.load(open(sys.argv[1])); assert j['counts']['done'] == 12 and len(j['cases']) == 12 and j['cases'][0]['angle_deg'] == 30, j" "$work/status.json" ||
  fail "study status --format json: $(cat "$work/status.json")"
"$bin" study status "$(dirname "$case_file")/../demo.toml" --db "$work/empty.db" --format csv > "$work/status.csv"
[ "$(head -1 "$work/status.csv")" = 'case,group,angle_deg,status,ranks,reached_s,last_error' ] ||
  fail "study status --format csv has no header row: $(head -2 "$work/status.csv")"
"$bin" case keys --format csv > "$work/keys.csv"
grep -q '^fluid.viscosity,0.001,Pa s,' "$work/keys.csv" || fail "case keys --format csv"
expect_usage "only \`case run\`" study status "$(dirname "$case_file")/../demo.toml" --db "$work/none.db" -- -ksp_view
"$bin" --help > /dev/null || fail "--help did not exit 0"
# case check shows the case's geometry, and an angle that looks like radians gets a warning.
"$bin" case check "$case_file" --set gravity.angle_deg=1.2 > "$work/out.txt" 2>&1 || fail "case check failed: $(cat "$work/out.txt")"
grep -q 'inclination 1.2 deg' "$work/out.txt" || fail "case check does not print the angle: $(cat "$work/out.txt")"
grep -q 'cells \[' "$work/out.txt" || fail "case check does not print the cells: $(cat "$work/out.txt")"
grep -q 'radians it is 68.75 degrees' "$work/out.txt" || fail "no radians warning: $(cat "$work/out.txt")"
"$bin" case check "$case_file" --set gravity.angle_deg=1 > "$work/out.txt" 2>&1
grep -q 'radians' "$work/out.txt" && fail "a whole-number angle warned of radians"
# An escape sequence in a value or a file name is printed escaped, never raw to the terminal.
printf 'scene = "sing\\u001b[31mle"\n' > "$work/esc.toml"
expect_usage 'sing\x1B[31mle' case check "$work/esc.toml"
expect_usage 'x\x1B[31m.toml' case check "$work/x$(printf '\033')[31m.toml"
if grep -q "$(printf '\033')" "$work/err.txt"; then fail "a raw escape reached stderr"; fi
# A new database in a folder that is not there: named, not created (a mistyped folder).
expect_usage "its folder '$work/nofolder' does not exist" study run "$(dirname "$case_file")/../demo.toml" --db "$work/nofolder/x.db"
[ ! -e "$work/nofolder" ] || fail "study run made the mistyped folder"
# A plan of more than 10 000 cases is one line per group unless --all.
{
  echo 'name = "big"'; echo '[base]'; echo 'scene = "inclined_settling"'; echo '[matrix]'
  echo '"gravity.angle_deg" = [10, 20, 30, 40, 50, 60, 70, 80, 90, 15, 25]'
  echo "\"seed\" = [$(seq -s, 1 100)]"
  echo '"fluid.viscosity" = [1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6e-3, 7e-3, 8e-3, 9e-3, 1e-2]'
} > "$work/big.toml"
"$bin" study plan "$work/big.toml" > "$work/plan.txt" || fail "plan of 11 000 cases failed"
grep -q 'one line per group' "$work/plan.txt" && [ "$(wc -l < "$work/plan.txt")" -lt 10 ] ||
  fail "a plan of 11 000 cases is not summarised: $(head -5 "$work/plan.txt")"
"$bin" study plan "$work/big.toml" --all > "$work/plan.txt"
[ "$(wc -l < "$work/plan.txt")" -gt 11000 ] || fail "plan --all does not list every case"
# status only reads: a database that does not exist (a mistyped path) is named, exit 2, none created.
demo=$(dirname "$case_file")/../demo.toml
expect_usage "no database at '$work/new.db'" study status "$demo" --db "$work/new.db"
grep -q 'study plan' "$work/err.txt" || fail "status on no database does not point to study plan: $(cat "$work/err.txt")"
[ ! -e "$work/new.db" ] || fail "status created a database"

# Not a terminal (stderr is a file): plain progress lines, the outcome, the unused PETSc option.
# A line is due every --progress-every wall seconds; 1 ns is less than any fluid step takes, so a
# line follows every step after the first whatever the machine's speed (the timing of the lines
# themselves is tested on a clock the test moves: test_case_progress.cpp).
"$bin" case run "$case_file" --out "$work/run" --set time.end=0.15 --set time.average_from=0.05 \
  --progress-every 1e-9 -- -pressure_ksp_typ cg > "$work/out.txt" 2> "$work/err.txt" || fail "the run failed: $(cat "$work/err.txt")"
n=$(grep -c '^progress: t = .* wall s per simulated s, ETA .*mean_wp_m_s' "$work/err.txt")
[ "$n" -ge 2 ] || fail "expected progress lines, got: $(cat "$work/err.txt")"
grep -q '^completed at t = 0.15 s after .* <<w_p>> = ' "$work/out.txt" || fail "no outcome line on stdout: $(cat "$work/out.txt")"
grep -q 'PETSc option -pressure_ksp_typ .* nothing used it' "$work/err.txt" || fail "unused PETSc option not reported"
grep -q 'no_signal_handler' "$work/err.txt" && fail "the program's own PETSc option reported as unused"
"$bin" case run "$case_file" --out "$work/quiet" --set time.end=0.05 --set time.average_from=0.02 --quiet \
  --progress-every 0.1 > /dev/null 2> "$work/err.txt" || fail "the quiet run failed"
grep -q '^progress:' "$work/err.txt" && fail "--quiet printed progress"
python3 - "$work/run/summary.json" <<'PY' || exit 1
import json, sys
b = json.load(open(sys.argv[1]))["build"]
for k in ("compiler", "flags", "petsc_version", "cpu_model", "build_type"):
    assert isinstance(b.get(k), str) and b[k], (k, b)
assert b["petsc_version"].count(".") == 2 and "-ffp-contract=off" in b["flags"], b
PY
echo "[ report ] usage errors exit 2 naming the word; $n progress lines in 0.15 s of simulated time"
