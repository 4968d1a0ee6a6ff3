#!/usr/bin/env bash
# kill -9 at random moments during a coupled run, then resume, over and over until the run
# completes: the final summary must equal, bitwise, that of an uninterrupted run (issue 5).
#   kill_resume.sh BOYCOTT_BIN CASE.toml [kills=20]
set -euo pipefail
bin=$1; case_file=$2; kills=${3:-20}
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
sets=(--set time.end=0.08 --set time.average_from=0.02 --set time.checkpoint_every=0.004)
"$bin" case run "$case_file" --out "$work/ref" "${sets[@]}" > /dev/null
RANDOM=12345
done_kills=0
while [ "$done_kills" -lt "$kills" ]; do
  "$bin" case run "$case_file" --out "$work/run" "${sets[@]}" > /dev/null 2>>"$work/err.txt" &
  pid=$!
  # 0.2 to 1.4 s: start-up, mid-step and mid-checkpoint moments all get hit.
  sleep "$(printf '0.%03d' $((RANDOM % 1000)))"; sleep "0.$((RANDOM % 5))"
  if kill -9 "$pid" 2>/dev/null; then done_kills=$((done_kills + 1)); fi
  wait "$pid" 2>/dev/null || true
  if [ -f "$work/run/summary.json" ] && grep -q '"completed"' "$work/run/summary.json"; then break; fi
done
# Finish (and resume once more if the last kill came before the end).
"$bin" case run "$case_file" --out "$work/run" "${sets[@]}" > /dev/null 2>>"$work/err.txt"
python3 - "$work" "$done_kills" <<'PY'
import json, sys, pathlib
w = pathlib.Path(sys.argv[1])
a = json.load(open(w / "ref" / "summary.json")); b = json.load(open(w / "run" / "summary.json"))
for k in ("mean_settling_velocity_m_s", "settling_velocity_stderr_m_s", "cfd_steps", "dem_steps",
          "mean_fluid_velocity_m_s", "max_abs_slurry_velocity_m_s", "simulated_time_s"):
    assert a[k] == b[k], (k, a[k], b[k])
ta = (w / "ref" / "timeseries.csv").read_text(); tb = (w / "run" / "timeseries.csv").read_text()
assert ta == tb, "time series differ"
print(f"[ report ] {sys.argv[2]} kill -9 and resumes: final summary and time series identical to the uninterrupted run")
PY
