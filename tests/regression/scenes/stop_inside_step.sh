#!/usr/bin/env bash
# A stop request inside a fluid step of 100 000 particle sub-steps (dt_dem = 1 ns): the run asks
# for stops every ~1e6 particle-steps of work (CoupledSystem::kStopCheckParticleSteps), drops
# the unfinished step, checkpoints the state at its start and exits 75; resumed, it ends with the
# same bits as a run never stopped. The signal is sent after the first checkpoint, while the run
# is (with >99 % of its time in sub-steps) almost surely inside a step; a stop that falls between
# steps is a plain stop, and the attempt is repeated (at most 4 times) until one falls inside.
# With RANKS > 1 under mpirun (which forwards the signal), the force budget on: every rank asks
# the same collective question at the same sub-step. The velocity profile is on in both: the
# checkpoint at the step's start carries its sums, and the resumed profile is the reference's.
#   stop_inside_step.sh BOYCOTT_BIN CASE.toml [RANKS]
set -uo pipefail
bin=$1; case_file=$2; ranks=${3:-1}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
launch=()
[ "$ranks" -gt 1 ] && launch=(mpirun -n "$ranks")
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
sets=(--set time.dt_dem=1e-9 --set time.dt_cfd=1e-4 --set time.end=0.0008 --set time.average_from=0.0001
      --set particles.volume_fraction=0.01 --set time.checkpoint_every=0.0003 --set output.velocity_profile_y=true)
[ "$ranks" -gt 1 ] && sets+=(--set output.force_budget_y=true)
"${launch[@]}" "$bin" case run "$case_file" --out "$work/ref" "${sets[@]}" --quiet > /dev/null 2>&1 || fail "the reference run failed"
inside=0
for attempt in 1 2 3 4; do
  dir="$work/stopped$attempt"
  "${launch[@]}" "$bin" case run "$case_file" --out "$dir" "${sets[@]}" > "$work/run$attempt.txt" 2> "$work/err$attempt.txt" &
  pid=$!
  until compgen -G "$dir/checkpoints/ckpt_*.h5" > /dev/null; do
    kill -0 "$pid" 2> /dev/null || break
    sleep 0.02
  done
  sleep 0.05
  kill -TERM "$pid" 2> /dev/null
  wait "$pid"; rc=$?
  [ "$rc" -eq 0 ] && continue  # the run ended before the signal: nothing to test in this attempt
  # (mpirun reports a rank's 75 as its own 1: the summary says what happened.)
  [ "$ranks" -gt 1 ] && grep -q '"interrupted"' "$dir/summary.json" && rc=75
  [ "$rc" -eq 75 ] || fail "stopped run exit $rc (expected 75): $(cat "$work/err$attempt.txt")"
  line=$(grep -m1 'stopped inside a fluid step' "$work/err$attempt.txt")
  "${launch[@]}" "$bin" case run "$case_file" --out "$dir" "${sets[@]}" --quiet > /dev/null 2>&1 || fail "the resume failed"
  if [ "$ranks" -gt 1 ]; then
    cmp -s "$work/ref/force_budget_y.csv" "$dir/force_budget_y.csv" || fail "the resumed force budget differs"
  fi
  cmp -s "$work/ref/timeseries.csv" "$dir/timeseries.csv" || fail "the resumed time series differs from the reference"
  cmp -s "$work/ref/velocity_profile_y.csv" "$dir/velocity_profile_y.csv" || fail "the resumed velocity profile differs"
  python3 - "$work/ref/summary.json" "$dir/summary.json" << 'PY' || fail "the resumed summary differs"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
for k in ("mean_settling_velocity_m_s", "simulated_time_s"):
    assert a[k] == b[k], (k, a[k], b[k])
PY
  if [ -n "$line" ]; then
    # "... after D of its 100000 particle sub-steps (asked every K, P particle-steps) ..."
    python3 - "$line" << 'PY' || fail "the stop was not asked often enough: $line"
import re, sys
m = re.search(r"after (\d+) of its (\d+) particle sub-steps \(asked every (\d+), ([0-9.e+]+) particle-steps\)", sys.argv[1])
done, total, every, work = int(m[1]), int(m[2]), int(m[3]), float(m[4])
assert total == 100000 and 0 < done < total and done % every == 0, m.groups()
assert work <= 1.0e6, work  # the stated bound: particle-steps between two checks
print(f"[ report ] stopped after {done} of {total} sub-steps, asked every {every} ({work:.3g} particle-steps); resumed bit for bit")
PY
    inside=1
    break
  fi
  echo "attempt $attempt: the signal fell between steps (a plain stop, resumed bit for bit); again"
done
[ "$inside" -eq 1 ] || fail "no attempt was stopped inside a step"
