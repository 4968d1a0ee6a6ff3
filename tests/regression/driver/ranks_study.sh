#!/usr/bin/env bash
# `boycott study run --ranks 2` launches each case under mpirun with 2 ranks: the attempts record
# 2 ranks, each summary says it ran on 2 MPI ranks, and the flow equals the 1-rank run's to the
# iteration tolerance (plane Poiseuille; SIMPLE stops at a relative change of 1e-6).
set -euo pipefail
bin=$1; study=$2
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$bin" study run "$study" --db "$work/two.sqlite" --jobs 1 --ranks 2 > "$work/two.txt"
"$bin" study run "$study" --db "$work/one.sqlite" --jobs 1 --ranks 1 > "$work/one.txt"
python3 - "$work" <<'PY'
import json, sqlite3, sys, pathlib
work = pathlib.Path(sys.argv[1])
for name, ranks in (("two", 2), ("one", 1)):
    db = sqlite3.connect(work / f"{name}.sqlite")
    rows = db.execute("select case_id, ranks, exit_status from attempts").fetchall()
    assert len(rows) == 2 and all(r[1] == ranks and r[2] == 0 for r in rows), rows
for d in (work / "two.sqlite.runs").iterdir():
    two = json.load(open(d / "summary.json"))
    one = json.load(open(work / "one.sqlite.runs" / d.name / "summary.json"))
    assert two["mpi_ranks"] == 2 and one["mpi_ranks"] == 1, (two["mpi_ranks"], one["mpi_ranks"])
    assert abs(two["max_rel_error_vs_analytic"] - one["max_rel_error_vs_analytic"]) < 1e-6, (two, one)
    assert abs(two["mean_velocity_m_s"] - one["mean_velocity_m_s"]) < 1e-6 * abs(one["mean_velocity_m_s"])
print("2-rank cases under mpirun equal the 1-rank ones")
PY
