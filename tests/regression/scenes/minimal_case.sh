#!/usr/bin/env bash
# `boycott case run` from a minimal case file of one scene: the scene, a small domain, a short
# time.end (and the averaging window where the scene averages: Table III's 5 s would not fit),
# nothing the scene does not read, and the scene's own defaults for the rest.
#   minimal_case.sh BOYCOTT_BIN SCENE
set -euo pipefail
bin=$1; scene=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
case "$scene" in
  inclined_settling | dem_only)
    body=$'[domain]\nlength_x = 0.01\nheight_z = 0.01\ncells = [10, 6, 10]\n[time]\nend = 0.02\naverage_from = 0.01'
    [ "$scene" = dem_only ] && body=${body/cells = \[10, 6, 10\]$'\n'/} ;;
  sediment_transport)
    body=$'[domain]\nlength_x = 0.005\nwidth_y = 0.01\nheight_z = 0.005\ncells = [5, 10, 5]\n[time]\nend = 0.01\naverage_from = 0.005' ;;
  single_particle)
    body=$'[domain]\nlength_x = 0.006\nheight_z = 0.006\ncells = [6, 6, 6]\n[time]\nend = 0.02\naverage_from = 0.01' ;;
  ergun)
    body=$'[particles]\ndiameter = 1.0e-3\n[domain]\nlength_x = 0.006\nwidth_y = 0.006\nheight_z = 0.006\ncells = [6, 6, 6]' ;;
  channel_flow)
    body=$'[domain]\nlength_x = 0.006\nheight_z = 0.006\ncells = [6, 6, 6]\n[time]\nend = 0.02' ;;
  *) echo "unknown scene $scene"; exit 2 ;;
esac
printf 'scene = "%s"\n%s\n' "$scene" "$body" > "$work/case.toml"
"$bin" case run "$work/case.toml" --out "$work/run" > "$work/out.txt" 2>&1 || { cat "$work/case.toml" "$work/out.txt"; exit 1; }
python3 - "$work/run/summary.json" "$scene" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
assert s["scene"] == sys.argv[2] and s["status"] == "completed", s
print(f"[ report ] {sys.argv[2]} from a minimal case file: {s['status']} in {s['wall_time_s']:.2f} s")
PY
