#!/usr/bin/env bash
# `study run --ranks 2` on a coupled case, stopped with SIGINT after the case's first checkpoint:
# the attempt is recorded as interrupted (exit 75; mpirun itself exits 1 on a forwarded signal),
# `study status` shows the case's 2 ranks and the simulated time it reached (reached_s, past its first
# checkpoint and short of its end), and the same command resumes the case to the end.
set -euo pipefail
bin=$1; case_file=$2
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cat > "$work/s.toml" <<TOML
name = "ranks_stop"
[base]
$(sed -n '/^scene/p' "$case_file")
[base.particles]
volume_fraction = 0.113
[base.domain]
length_x = 0.02
width_y = 0.006
height_z = 0.02
cells = [20, 6, 20]
[base.time]
end = 0.3
average_from = 0.1
checkpoint_every = 0.05
[[group]]
name = "g"
[matrix]
"gravity.angle_deg" = [60]
TOML
cd "$work"
"$bin" study run s.toml --db s.db --ranks 2 > out1.txt 2>&1 &
pid=$!
until compgen -G "s.db.runs/*/checkpoints/ckpt_*.h5" > /dev/null; do
  kill -0 "$pid" 2> /dev/null || { echo "the study ended before the first checkpoint"; cat out1.txt; exit 1; }
  sleep 0.02
done
kill -INT "$pid"
rc=0; wait "$pid" || rc=$?
[ "$rc" -eq 75 ] || { echo "driver exit $rc, expected 75"; cat out1.txt; exit 1; }
"$bin" study status s.toml --db s.db > status.txt
"$bin" study run s.toml --db s.db --ranks 2 > out2.txt 2>&1
python3 - "$work" <<'PY'
import sqlite3, sys, pathlib
w = pathlib.Path(sys.argv[1])
rows = sqlite3.connect(w / "s.db").execute("select ranks, exit_status from attempts order by id").fetchall()
assert rows == [(2, 75), (2, 0)], rows
status = (w / "status.txt").read_text().splitlines()
assert "ranks" in status[1] and status[2].split()[4] == "2", status
assert status[1].split()[5] == "reached_s" and 0.05 <= float(status[2].split()[5]) < 0.3, status
print(f"[ report ] attempts {rows}: the stop under mpirun recorded as interrupted, resumed to the end on 2 ranks")
PY
