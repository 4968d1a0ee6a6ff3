#!/usr/bin/env python3
"""The most any automatic window can see of a weak start-up transient (docs/validation.md).

For the coverage tests' series families (tests/unit/series_families.hpp: AR(1) of tau_int 10
steps; two AR(1) processes 3-30x apart in time, the slow one carrying 0.1-0.5 of the variance;
a damped oscillation plus white noise) with a start-up decay A exp(-t / (5 slowest times)) that
biases the window's mean by `bias` true standard errors, this prints the Neyman-Pearson bound on
the share of such series that any rule can cut while it cuts at most `alpha` of stationary ones.
The bound is the best test there is: it knows the family's exact covariance and the transient's
exact shape, and only the mean is unknown. Its statistic is the matched filter; with d' =
sqrt(s' S^-1 s - (1' S^-1 s)^2 / 1' S^-1 1) (s the transient, S the covariance, the mean
projected out) it detects with probability Phi(d' - z_(1 - alpha)). A rule that must find the
transient without knowing its shape or the series' correlation does worse. A transient that is
not seen is not cut, and leaves its whole bias, so the bound also caps the share of series left
with less than half a standard error of bias.

S^-1 products come from a Kalman filter on each family's state-space form (linear in the series'
length). Parameters are drawn per series as the families draw them (fixed seed).

    scripts/transient_power_bound.py [--window 50] [--bias 1] [--alpha 0.1] [--draws 300]
"""
import argparse
import math
import random


def phi(x):
    return 0.5 * (1.0 + math.erf(x / math.sqrt(2.0)))


def z_quantile(p):
    lo, hi = -10.0, 10.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if phi(mid) < p else (lo, mid)
    return 0.5 * (lo + hi)


def whiten(model, signals):
    """Each signal's Kalman innovations over their standard deviations: L^-1 s with S = L L'."""
    T, Q, Z, H, P0 = model
    n = len(signals[0])
    a = [[0.0, 0.0] for _ in signals]
    P = [row[:] for row in P0]
    out = [[0.0] * n for _ in signals]
    for t in range(n):
        # F = Z P Z' + H, K = T P Z' / F
        PZ = [P[0][0] * Z[0] + P[0][1] * Z[1], P[1][0] * Z[0] + P[1][1] * Z[1]]
        F = Z[0] * PZ[0] + Z[1] * PZ[1] + H
        sf = math.sqrt(F)
        for k, s in enumerate(signals):
            nu = s[t] - (Z[0] * a[k][0] + Z[1] * a[k][1])
            out[k][t] = nu / sf
            upd = [a[k][0] + PZ[0] * nu / F, a[k][1] + PZ[1] * nu / F]
            a[k] = [T[0][0] * upd[0] + T[0][1] * upd[1], T[1][0] * upd[0] + T[1][1] * upd[1]]
        # P <- T (P - PZ PZ' / F) T' + Q
        M = [[P[i][j] - PZ[i] * PZ[j] / F for j in range(2)] for i in range(2)]
        TM = [[T[i][0] * M[0][j] + T[i][1] * M[1][j] for j in range(2)] for i in range(2)]
        P = [[TM[i][0] * T[j][0] + TM[i][1] * T[j][1] + Q[i][j] for j in range(2)] for i in range(2)]
    return out


def ar1_phi(tau):
    return (2.0 * tau - 1.0) / (2.0 * tau + 1.0)


def ar1(rng):
    tau = 10.0
    f = ar1_phi(tau)
    model = ([[f, 0.0], [0.0, 0.0]], [[1.0 - f * f, 0.0], [0.0, 0.0]], [1.0, 0.0], 0.0, [[1.0, 0.0], [0.0, 0.0]])
    return model, tau, tau


def two_scales(rng):
    tau_fast = 2.0 + 3.0 * rng.random()
    ratio = 3.0 * 10.0 ** rng.random()
    share = 0.1 + 0.4 * rng.random()
    tau_slow = ratio * tau_fast
    ff, fs = ar1_phi(tau_fast), ar1_phi(tau_slow)
    model = ([[ff, 0.0], [0.0, fs]], [[(1.0 - ff * ff) * (1.0 - share), 0.0], [0.0, (1.0 - fs * fs) * share]],
             [1.0, 1.0], 0.0, [[1.0 - share, 0.0], [0.0, share]])
    return model, (1.0 - share) * tau_fast + share * tau_slow, tau_slow


def oscillation(rng):
    period = 8.0 + 32.0 * rng.random()
    decay = period * (1.0 + 3.0 * rng.random())
    share = 0.4 + 0.4 * rng.random()
    r = math.exp(-1.0 / decay)
    a1, a2 = 2.0 * r * math.cos(2.0 * math.pi / period), -r * r
    var = (1.0 - a2) / ((1.0 + a2) * ((1.0 - a2) ** 2 - a1 * a1))
    tau_ar2 = 1.0 / ((1.0 - a1 - a2) ** 2 * var) / 2.0
    scale2 = share / var
    g1 = a1 / (1.0 - a2) * share  # lag-1 covariance of the scaled AR(2)
    model = ([[a1, a2], [1.0, 0.0]], [[scale2, 0.0], [0.0, 0.0]], [1.0, 0.0], 1.0 - share,
             [[share, g1], [g1, share]])
    return model, share * tau_ar2 + (1.0 - share) / 2.0, decay


def d_prime(model, tau_int, slowest, window, bias):
    n = int(window * slowest)
    decay = 5.0 * slowest
    shape = [math.exp(-i / decay) for i in range(n)]
    amp = bias * math.sqrt(2.0 * tau_int / n) * n / sum(shape)
    ws, w1 = whiten(model, [[amp * x for x in shape], [1.0] * n])
    ss = sum(x * x for x in ws)
    s1 = sum(x * y for x, y in zip(ws, w1))
    oo = sum(y * y for y in w1)
    return math.sqrt(max(ss - s1 * s1 / oo, 0.0))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--window", type=float, default=50.0, help="window in slowest times")
    ap.add_argument("--bias", type=float, default=1.0, help="transient's bias of the mean, true standard errors")
    ap.add_argument("--alpha", type=float, default=0.1, help="share of stationary series a rule may cut")
    ap.add_argument("--draws", type=int, default=300, help="parameter draws per family")
    ap.add_argument("--seed", type=int, default=61)
    args = ap.parse_args()
    z = z_quantile(1.0 - args.alpha)
    print(f"window {args.window:g} slowest times, transient biasing the mean by {args.bias:g} standard errors, "
          f"decay 5 slowest times, at most {args.alpha:g} of stationary series cut")
    print("family       d' (median, 10-90 %)   bound on the share seen   bias (SE) the bound reaches 0.9 at")
    for name, draw in (("ar1", ar1), ("two_scales", two_scales), ("oscillation", oscillation)):
        rng = random.Random(args.seed)
        draws = 1 if name == "ar1" else args.draws
        ds = sorted(d_prime(*draw(rng), args.window, args.bias) for _ in range(draws))
        seen = sum(phi(d - z) for d in ds) / len(ds)
        q = lambda p: ds[min(int(p * len(ds)), len(ds) - 1)]
        need = (z + z_quantile(0.9)) / q(0.5) * args.bias
        print(f"{name:12s} {q(0.5):6.2f} ({q(0.1):.2f}-{q(0.9):.2f})      {seen:6.3f}                    {need:.2f}")


if __name__ == "__main__":
    main()
