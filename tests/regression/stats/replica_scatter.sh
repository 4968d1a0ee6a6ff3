#!/usr/bin/env bash
# Physics of the error bar: 32 replicas of a cheap inclined case (replica_scatter_study.toml). If
# each run's own error is honest, it predicts the scatter of the replicas' <<w_p>>.
#
# The statistic: R^2 = s^2 / (pooled e^2), s the sample standard deviation of the replicas' means
# (n - 1 degrees of freedom) and e_i each run's own plain standard error with its own degrees of
# freedom nu_i (summary.json settling_velocity_error_dof; a window's two halves give 1), pooled as
# sum nu_i e_i^2 / sum nu_i. Replicas of one case share one true error sigma, so for Gaussian
# means s^2 / sigma^2 ~ chi2_{n-1} / (n-1) and pooled e^2 / sigma^2 ~ chi2_{sum nu} / sum nu,
# independent (a window's mean and the difference of its halves are), and R^2 ~ F(n - 1, sum nu)
# exactly when the errors are honest. The bounds are F's 0.1 % and 99.9 % quantiles: a change that
# only moves round-off (and so reshuffles every replica) fails it with probability 0.2 %.
# Why 32 replicas: with 1-degree errors the statistic of 8 spreads so widely (measured 0.55-1.89
# over 12 sets of 8 seeds, honest at 48: 0.99 and 1.01) that the 0.1 % bounds are [0.26, 3.52]
# and errors off by 2x fail one time in 15; at 32 they are [0.57, 1.76] and errors off by 2x either
# way fail 3 times in 4, by 1.5x about 1 in 5 (docs/validation.md, "Error bars: do they cover?").
set -euo pipefail
bin=$1; study=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$bin" study run "$study" --db "$work/s.sqlite" --jobs 2 > "$work/out.txt"
"$bin" query curve --db "$work/s.sqlite" --study replica_scatter --format json > "$work/curve.json"
python3 - "$work" <<'PY'
import json, math, sys, pathlib

def incomplete_beta(a, b, x):
    """Regularized I_x(a, b) by its continued fraction (modified Lentz), an oracle written apart
    from the product's stats/distributions.cpp."""
    if x <= 0.0: return 0.0
    if x >= 1.0: return 1.0
    if x > (a + 1.0) / (a + b + 2.0): return 1.0 - incomplete_beta(b, a, 1.0 - x)
    tiny = 1e-300
    front = math.exp(math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b)
                     + a * math.log(x) + b * math.log1p(-x)) / a
    c, d = 1.0, 0.0
    f = tiny
    for i in range(0, 400):
        m = i // 2
        if i == 0: num = 1.0
        elif i % 2 == 0: num = m * (b - m) * x / ((a + 2 * m - 1) * (a + 2 * m))
        else: num = -(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1))
        d = 1.0 + num * d; d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + num / c; c = c if abs(c) > tiny else tiny
        f = (f if i else 1.0) * c * d
        if i and abs(c * d - 1.0) < 1e-14: break
    return front * (f - 1.0)

def f_cdf(x, d1, d2): return incomplete_beta(d1 / 2.0, d2 / 2.0, d1 * x / (d1 * x + d2))

def f_quantile(p, d1, d2):
    lo, hi = 0.0, 1.0
    while f_cdf(hi, d1, d2) < p: hi *= 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f_cdf(mid, d1, d2) < p else (lo, mid)
    return 0.5 * (lo + hi)

# The oracle against printed tables: F(5, 10) 95 % 3.326, F(7, 8) 99.9 % 12.40, F(1, 1) 50 % 1.
for p, d1, d2, want in ((0.95, 5, 10, 3.3258), (0.999, 7, 8, 12.40), (0.5, 1, 1, 1.0)):
    got = f_quantile(p, d1, d2)
    assert abs(got - want) < 2e-3 * want, (p, d1, d2, got, want)

work = pathlib.Path(sys.argv[1])
curve = json.load(open(work / "curve.json"))
assert len(curve) == 1, curve
p = curve[0]
n = p["n_replicas"]
assert n == 32, p
# Each run's own error: gapped batch means, or (below 60 correlation times, counted
# conservatively) its window's two halves; never the ungapped batch means of older builds.
assert p["error_method"] in ("gapped_batch_means", "two_halves", "mixed"), p["error_method"]
w, e2nu, nu = [], 0.0, 0.0
for cid in p["replica_case_ids"]:
    s = json.load(open(work / "s.sqlite.runs" / cid / "summary.json"))
    seed = json.load(open(work / "s.sqlite.runs" / cid / "params.json")).get("seed", "?")
    e, dof = s["settling_velocity_stderr_m_s"], s["settling_velocity_error_dof"]
    assert e > 0.0 and dof >= 1.0, (cid, e, dof)
    w.append(s["mean_settling_velocity_m_s"])
    e2nu += dof * e * e
    nu += dof
    print(f"[ report ] seed {seed}: <<w_p>> {w[-1] * 1e3:.2f} mm/s +- {e * 1e3:.2f} "
          f"({s['settling_velocity_error_method']}, {dof:g} dof; tau_int {s['settling_velocity_correlation_time_s']:.3f} s, "
          f"{s['settling_velocity_window_correlation_times']:.1f} correlation times)")
mean = sum(w) / n
sd = math.sqrt(sum((x - mean) ** 2 for x in w) / (n - 1))
pooled = math.sqrt(e2nu / nu)
ratio = sd / pooled
lo, hi = math.sqrt(f_quantile(0.001, n - 1, nu)), math.sqrt(f_quantile(0.999, n - 1, nu))
# The database's between-replica error is the same scatter: sd / sqrt(n).
assert abs(p["between_replica_stderr_m_s"] * math.sqrt(n) - sd) < 1e-9 * abs(mean), (p, sd)
print(f"[ report ] {n} replicas, mean {mean * 1e3:.2f} mm/s, sd {sd * 1e3:.3f} mm/s; pooled own error "
      f"{pooled * 1e3:.3f} mm/s ({nu:g} dof); ratio {ratio:.3f}, F({n - 1}, {nu:g}) bounds "
      f"[{lo:.3f}, {hi:.3f}], P(F <= ratio^2) = {f_cdf(ratio * ratio, n - 1, nu):.3f}")
assert lo <= ratio <= hi, (ratio, lo, hi)
PY
