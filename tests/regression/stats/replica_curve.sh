#!/usr/bin/env bash
# A real replica study (replica_tiny_study.toml) through `boycott study run`; the curve's
# between-replica error, mean, mean within-run error and r_acc error are recomputed here from the
# database rows alone (results joined to the cases' stored parameters), grouping the replicas by
# their angle and checking that they differ only in their seed, which is seed + k. A study that
# also sweeps the seed is refused first.
set -euo pipefail
bin=$1; study=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
# Replicas with a swept seed: refused (exit 2) with a message naming both, nothing written.
{ cat "$study"; printf 'seed = [1, 2]\n'; } > "$work/seeds.toml"
rc=0; "$bin" study run "$work/seeds.toml" --db "$work/seeds.sqlite" > "$work/seeds.txt" 2>&1 || rc=$?
[ "$rc" = 2 ] || { echo "replicas with a swept seed: exit $rc, expected 2"; cat "$work/seeds.txt"; exit 1; }
grep -q "replicas = 3 runs replica k with seed + k, and the study also varies 'seed'" "$work/seeds.txt" \
  || { echo "no message naming replicas and the swept seed:"; cat "$work/seeds.txt"; exit 1; }
[ ! -e "$work/seeds.sqlite" ] || { echo "a refused study wrote its database"; exit 1; }
"$bin" study run "$study" --db "$work/s.sqlite" --jobs 2 > "$work/out.txt"
for f in json csv; do
  "$bin" query curve --db "$work/s.sqlite" --study replica_tiny --format $f > "$work/curve.$f"
done
python3 - "$work" <<'PY'
import csv, json, math, sqlite3, sys, pathlib
work = pathlib.Path(sys.argv[1])
db = sqlite3.connect(work / "s.sqlite")
rows = db.execute(
    "SELECT c.id, c.angle_deg, c.params_json, r.mean_settling_velocity_m_s, "
    "r.settling_velocity_stderr_m_s FROM results r JOIN cases c ON c.id = r.case_id "
    "JOIN study_cases sc ON sc.case_id = c.id WHERE sc.study = 'replica_tiny'").fetchall()
assert len(rows) == 9, rows
by_angle = {}
for cid, angle, params, w, e in rows:
    p = json.loads(params)
    seed = p.pop("seed")
    by_angle.setdefault(angle, []).append((seed, p, w, e, cid))
stats = {}
for angle, reps in by_angle.items():
    reps.sort(key=lambda r: r[0])
    assert [r[0] for r in reps] == [1, 2, 3], (angle, [r[0] for r in reps])
    assert all(r[1] == reps[0][1] for r in reps), "replicas differ in more than their seed"
    w = [r[2] for r in reps]
    n = len(w)
    m = sum(w) / n
    sd = math.sqrt(sum((x - m) ** 2 for x in w) / (n - 1))
    # Off the vertical, contacts with the wall and each other depend on the seed.
    if angle != 90.0:
        assert sd > 1e-3 * abs(m), ("replicas with different seeds gave the same result", angle, w)
    stats[angle] = dict(mean=m, between=sd / math.sqrt(n), within=sum(r[3] for r in reps) / n,
                        ids=sorted(r[4] for r in reps))
curve = json.load(open(work / "curve.json"))
assert len(curve) == 3, curve
table = {float(r["angle_deg"]): r for r in csv.DictReader(open(work / "curve.csv"))}
def close(a, b, rel=1e-12):
    assert abs(a - b) <= rel * abs(b), (a, b)
def t_cdf(t, nu, steps=20000):
    # Student's t density integrated from 0 to t (Simpson), written out independently of the product.
    c = math.exp(math.lgamma((nu + 1) / 2) - math.lgamma(nu / 2)) / math.sqrt(nu * math.pi)
    f = lambda x: c * (1 + x * x / nu) ** (-(nu + 1) / 2)
    h = t / steps
    return 0.5 + h / 3 * sum((1 if k in (0, steps) else 4 if k % 2 else 2) * f(k * h) for k in range(steps + 1))
def t68(nu):
    lo, hi = 0.0, 10.0
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if t_cdf(mid, nu, 2000) < (1 + 0.682689492137086) / 2 else (lo, mid)
    return (lo + hi) / 2
w90, e90 = stats[90.0]["mean"], stats[90.0]["between"]
for row in curve:
    s = stats[row["angle_deg"]]
    assert row["n_replicas"] == 3, row
    assert sorted(row["replica_case_ids"]) == s["ids"], row
    close(row["mean_settling_velocity_m_s"], s["mean"])
    close(row["between_replica_stderr_m_s"], s["between"])
    close(row["stderr_m_s"], s["between"])
    # The covering error: t at n - 1 = 2 degrees of freedom times sd/sqrt(n), or the larger pooled
    # within-run error where the replicas' scatter and their own errors disagree (said in the basis).
    if row["error_basis"] == "between_replicas_t":
        close(row["error_m_s"], t68(2) * s["between"], 1e-6)
    else:
        assert row["error_basis"].startswith(("between_replicas_t; ", "within_runs_pooled; ")), row
        assert row["error_m_s"] >= t68(2) * s["between"] * (1 - 1e-6), row
    close(row["mean_within_run_stderr_m_s"], s["within"])
    c = table[row["angle_deg"]]
    assert int(c["n_replicas"]) == 3
    close(float(c["between_replica_stderr_m_s"]), s["between"], 1e-8)
    close(float(c["mean_within_run_stderr_m_s"]), s["within"], 1e-8)
    r = s["mean"] / w90
    close(row["r_acc"], r)
    plain = [x for x in curve if x["angle_deg"] == 90.0][0]["error_basis"] == "between_replicas_t"
    if row["angle_deg"] != 90.0 and plain and row["error_basis"] == "between_replicas_t":
        # Welch-Satterthwaite over the two points' sd/sqrt(n) (2 degrees of freedom each), then t.
        a, b = s["between"] / w90, r * e90 / w90
        nu = (a * a + b * b) ** 2 / (a ** 4 / 2 + b ** 4 / 2)
        close(row["r_acc_err"], math.hypot(a, b) * t68(nu), 1e-6)
    print(f"angle {row['angle_deg']:g}: mean {s['mean']:.6g} m/s, between-replica error "
          f"{s['between']:.3g}, mean within-run error {s['within']:.3g}")
print("curve matches the database rows")
PY
