#!/usr/bin/env bash
# Physics of the error bar: 8 replicas of a cheap inclined case (replica_scatter_study.toml). If
# each run's own error (integrated autocorrelation time) is honest, it predicts the scatter of the
# replicas' <<w_p>>. Like is compared with like: the curve's between-replica error is the error of
# the mean of N replicas, sd/sqrt(N), and its mean within-run error is one run's, so the ratio is
# between-replica error x sqrt(N) / mean within-run error = sd of the replica means / one run's
# error, required in [0.5, 1.6] (with 8 replicas the sd itself scatters by about 27 %).
set -euo pipefail
bin=$1; study=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$bin" study run "$study" --db "$work/s.sqlite" --jobs 2 > "$work/out.txt"
"$bin" query curve --db "$work/s.sqlite" --study replica_scatter --format json > "$work/curve.json"
python3 - "$work" <<'PY'
import json, math, sys, pathlib
work = pathlib.Path(sys.argv[1])
curve = json.load(open(work / "curve.json"))
assert len(curve) == 1, curve
p = curve[0]
assert p["n_replicas"] == 8, p
# Each run's own error: gapped batch means, or (below 60 correlation times, counted
# conservatively) its window's two halves; never the ungapped batch means of older builds.
assert p["error_method"] in ("gapped_batch_means", "two_halves", "mixed"), p["error_method"]
for cid in p["replica_case_ids"]:
    s = json.load(open(work / "s.sqlite.runs" / cid / "summary.json"))
    seed = json.load(open(work / "s.sqlite.runs" / cid / "params.json")).get("seed", "?")
    print(f"[ report ] seed {seed}: <<w_p>> {s['mean_settling_velocity_m_s'] * 1e3:.2f} mm/s "
          f"+- {s['settling_velocity_stderr_m_s'] * 1e3:.2f} ({s['settling_velocity_error_method']}; tau_int {s['settling_velocity_correlation_time_s']:.3f} s, "
          f"{s['settling_velocity_window_correlation_times']:.1f} correlation times)")
between, within = p["between_replica_stderr_m_s"], p["mean_within_run_stderr_m_s"]
assert within is not None and between is not None, p
sd = between * math.sqrt(p["n_replicas"])
ratio = sd / within
print(f"[ report ] between-replica error {between * 1e3:.3f} mm/s (sd of the replicas {sd * 1e3:.3f} mm/s), "
      f"mean within-run error {within * 1e3:.3f} mm/s, ratio sd / within {ratio:.2f}")
assert 0.5 <= ratio <= 1.6, ratio
PY
