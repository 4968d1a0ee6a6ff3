#!/usr/bin/env bash
# Extending and branching runs.
#  - A finished case whose time.end is raised continues from its newest checkpoint and ends with
#    the time series and summary of a run straight to the new end; asked again with the same end
#    it says so and exits 0; a lower end is refused naming both times.
#  - A study whose end is raised continues its finished cases to the same results.
#  - `case run --from DIR --at T` starts from DIR's newest checkpoint at or before T with other
#    physics and records its parent; what cannot change mid-run is refused naming the parameter.
#   extend_branch.sh BOYCOTT_BIN CASE.toml
set -euo pipefail
bin=$1; case_file=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
base=(--set time.average_from=0.04 --set time.checkpoint_every=0.05 --set output.timeseries_every=0.007)
run() { "$bin" case run "$case_file" "${base[@]}" "$@"; }
# Extension
run --out "$work/ext" --set time.end=0.1 > /dev/null 2>&1
run --out "$work/ext" --set time.end=0.16 > /dev/null 2> "$work/ext.err"
run --out "$work/direct" --set time.end=0.16 > /dev/null 2>&1
cmp "$work/ext/timeseries.csv" "$work/direct/timeseries.csv"
cp "$work/ext/summary.json" "$work/ext.summary"
rc=0; run --out "$work/ext" --set time.end=0.16 > /dev/null 2> "$work/again.err" || rc=$?
[ "$rc" -eq 0 ] && grep -q "already complete" "$work/again.err" && cmp "$work/ext/summary.json" "$work/ext.summary"
rc=0; run --out "$work/ext" --set time.end=0.05 > /dev/null 2> "$work/lower.err" || rc=$?
[ "$rc" -eq 2 ] && grep -q "time.end = 0.05 s is below the time this run reached, 0.16" "$work/lower.err"
# Study extension
study() {  # end db
  cat > "$work/s$1.toml" <<TOML
name = "ext"
[base]
$(grep -v '^#' "$case_file" | sed 's/^\[/[base./' | grep -v '^\[base.time\]' | grep -v '^end\|^average_from')
[base.time]
end = $1
average_from = 0.04
checkpoint_every = 0.05
[matrix]
"gravity.angle_deg" = [50, 80]
TOML
  "$bin" study run "$work/s$1.toml" --db "$work/$2" > /dev/null 2>&1
}
study 0.1 cont.db; study 0.16 cont.db; study 0.16 direct.db
# Branch
run --out "$work/parent" --set time.end=0.1 > /dev/null 2>&1
run --out "$work/child" --set time.end=0.15 --set fluid.viscosity=2e-3 --from "$work/parent" --at 0.07 > /dev/null 2> "$work/child.err"
refuse() {  # expected text, arguments
  local want=$1; shift; local rc=0
  run --out "$work/refused" --set time.end=0.15 --from "$work/parent" "$@" > /dev/null 2> "$work/refused.err" || rc=$?
  [ "$rc" -eq 2 ] && grep -q "$want" "$work/refused.err" || { echo "not refused ($want): exit $rc"; cat "$work/refused.err"; exit 1; }
  [ ! -e "$work/refused" ] || { echo "a refused branch wrote $work/refused"; exit 1; }
}
refuse "particles.count cannot change" --set particles.count=2000
refuse "domain.cells cannot change" --set 'domain.cells=[10, 6, 20]'
refuse "particles.diameter (larger) cannot change" --set particles.diameter=0.7e-3 --set particles.count=2398
refuse "keeps checkpoints at" --at 0.01
python3 - "$work" <<'PY'
import json, sqlite3, sys, pathlib
w = pathlib.Path(sys.argv[1])
a = json.load(open(w / "ext" / "summary.json")); b = json.load(open(w / "direct" / "summary.json"))
keys = ("mean_settling_velocity_m_s", "settling_velocity_stderr_m_s", "cfd_steps", "dem_steps", "simulated_time_s",
        "mean_fluid_velocity_m_s", "max_abs_slurry_velocity_m_s", "max_kinetic_energy_j")
for k in keys:
    assert a[k] == b[k], (k, a[k], b[k])
rows = {}
for name in ("cont", "direct"):
    db = sqlite3.connect(w / f"{name}.db")
    rows[name] = sorted(db.execute("select case_id, mean_settling_velocity_m_s, average_to_s from results"))
    att = db.execute("select case_id, exit_status from attempts").fetchall()
    assert len(att) == (4 if name == "cont" else 2) and all(x[1] == 0 for x in att), att
assert rows["cont"] == rows["direct"], rows
c = json.load(open(w / "child" / "summary.json")); p = json.load(open(w / "parent" / "summary.json"))
assert c["status"] == "completed" and c["parent"]["case_id"] == p["case_id"], c.get("parent")
assert abs(c["parent"]["time_s"] - 0.05) < 1e-9, c["parent"]  # the checkpoint at or before --at 0.05
assert c["case_id"] != p["case_id"]
# A branch's models are timed over its own steps, from its parent's time; an extended run's over
# all its attempts, from the start.
assert c["model_times_from_s"] == c["parent"]["time_s"], (c["model_times_from_s"], c["parent"])
assert a["model_times_from_s"] == 0.0 and b["model_times_from_s"] == 0.0, a["model_times_from_s"]
print(f"[ report ] extended 0.1 -> 0.16 s: time series and summary identical to a run straight to 0.16 s "
      f"(<<w_p>> {a['mean_settling_velocity_m_s']:.9g}); a study raised from 0.1 to 0.16 s gives the same results "
      f"{[r[1] for r in rows['cont']]}; a branch at viscosity 2e-3 from t = {c['parent']['time_s']} s completed, "
      f"parent {c['parent']['case_id']}")
PY
