#!/usr/bin/env bash
# A new scene is one file plus one line in a CMake list: a program linked exactly as `boycott` is,
# plus a library holding one more scene file (one_file_scene/free_fall.cpp, linked the way the
# scenes are), lists the new scene's keys, runs it, and still knows every scene of `boycott`;
# `boycott` itself does not know the test's scene.
#   one_file_scene.sh BOYCOTT_BIN PROGRAM_WITH_THE_TEST_SCENE
set -euo pipefail
bin=$1; plus=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$plus" case keys --scene free_fall > "$work/keys.txt" || fail "case keys --scene free_fall: exit $?"
grep -q '^scene free_fall: one sphere falling in vacuum' "$work/keys.txt" || { cat "$work/keys.txt"; fail "no scene line"; }
for k in gravity.angle_deg gravity.magnitude time.dt_dem time.end; do
  grep -q "^$k " "$work/keys.txt" || { cat "$work/keys.txt"; fail "free_fall does not list $k"; }
done
if grep -q '^fluid\.' "$work/keys.txt"; then fail "free_fall lists a key it does not read"; fi

# Every scene of boycott is in the larger program too, and boycott does not have the test's.
"$bin" case keys --format json > /dev/null
scenes=$("$bin" case keys --format json | python3 -c 'import json,sys; print(" ".join(next(r["meaning"] for r in json.load(sys.stdin) if r["key"] == "scene").split("one of ")[1].split(", ")))')
for s in $scenes; do
  "$plus" case keys --scene "$s" > /dev/null || fail "the larger program lost scene $s"
done
[ "$(echo $scenes | wc -w)" -ge 6 ] || fail "boycott lists only: $scenes"
if "$bin" case keys --scene free_fall > "$work/refused.txt" 2>&1; then fail "boycott knows free_fall"; fi
grep -q 'scene = "free_fall" is not known' "$work/refused.txt" || { cat "$work/refused.txt"; fail "refusal"; }

# Its own check refuses, its run runs.
printf 'scene = "free_fall"\n[gravity]\nangle_deg = 0.0\n[time]\nend = 0.1\n' > "$work/flat.toml"
set +e; "$plus" case run "$work/flat.toml" --out "$work/flat" > "$work/flat.txt" 2>&1; rc=$?; set -e
[ "$rc" = 2 ] || { cat "$work/flat.txt"; fail "the scene's own check: exit $rc, not 2"; }
grep -q 'nothing falls along z' "$work/flat.txt" || { cat "$work/flat.txt"; fail "own check's message"; }
printf 'scene = "free_fall"\n[gravity]\nangle_deg = 30.0\n[time]\nend = 0.1\ndt_dem = 1.0e-3\n' > "$work/case.toml"
"$plus" case run "$work/case.toml" --out "$work/run" > "$work/out.txt" 2>&1 || { cat "$work/out.txt"; fail "case run"; }
python3 - "$work/run/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
assert s["scene"] == "free_fall" and s["status"] == "completed", s
v, exact = s["mean_settling_velocity_m_s"], s["analytic_velocity_m_s"]
# -9.81 sin(30 deg) 0.1 s = -0.4905 m/s; 100 steps of 1 ms sum the same to round-off
assert abs(exact + 0.4905) < 1e-9 and abs(v - exact) < 1e-12, (v, exact)
print(f"[ report ] free_fall from its one file: v {v:.6f} m/s (analytic {exact:.6f})")
PY
