#!/usr/bin/env bash
# A database and run folders written by the release before case identity version 2
# (fixtures/migr_v1.tar.gz: a two-case study, 60 deg finished, 90 deg interrupted after a
# checkpoint) opened by `study run`: the ids and folders are migrated, the finished case is not
# run again, the interrupted one resumes from its checkpoint, and a second run changes nothing.
set -euo pipefail
bin=$1; fixture=$2
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cd "$work"
tar xzf "$fixture"
# The release that wrote the fixture ran Saffman's lift as printed, one SIMPLE corrector and no
# packed-bed step limit, the defaults then: the study names them, so its cases are the stored
# ones (a study left on today's defaults has other cases and would run them).
printf '[base.forces]\nlift = "saffman"\n[base.numerics]\nsimple_correctors = 1\ndrag_dt_limit = false\n' >> migr.toml
old_ids=$(sqlite3 migr.sqlite "select id from cases order by angle_deg" | tr '\n' ' ')
"$bin" study run migr.toml --db migr.sqlite > out1.txt 2> err1.txt
"$bin" study run migr.toml --db migr.sqlite > out2.txt 2> err2.txt
python3 - "$work" "$old_ids" <<'PY'
import json, sqlite3, sys, pathlib
w = pathlib.Path(sys.argv[1]); old = sys.argv[2].split()
db = sqlite3.connect(w / "migr.sqlite")
ids = [r[0] for r in db.execute("select id from cases order by angle_deg")]
assert len(ids) == 2 and not set(ids) & set(old), (ids, old)
assert db.execute("select value from meta where key = 'case_id_version'").fetchone() == ("2",)
att = db.execute("select case_id, exit_status from attempts order by id").fetchall()
# 60 deg: its one finished attempt only; 90 deg: interrupted (75), then resumed to the end.
assert att == [(ids[0], 0), (ids[1], 75), (ids[1], 0)], att
assert db.execute("select count(*) from results").fetchone() == (2,)
runs = w / "migr.sqlite.runs"
assert sorted(p.name for p in runs.iterdir()) == sorted(ids), list(runs.iterdir())
s = json.load(open(runs / ids[1] / "summary.json"))
assert s["resumed_from_checkpoint"] and s["status"] == "completed", s
print(f"[ report ] ids {old} -> {ids}; attempts {att}; the interrupted case resumed from its checkpoint")
PY
grep -q "case identity version 2: 2 case ids recomputed" err1.txt
! grep -q "recomputed" err2.txt
