#!/usr/bin/env python3
"""The stages of Fig. 8 (Zeng et al. 2021) in an inclined_settling run's <w_p>(t).

Reads DIR/timeseries.csv (time_s, mean_wp_m_s) and prints, with settling speed s = -<w_p>:
  stage I   stratified acceleration: s rises from 0 to its first peak (t_peak, s_peak);
  stage II  resuspension: s falls from the peak to the following minimum (t_trough, s_trough);
  stage III secondary instability: s rises again after the trough (re-acceleration, if the
            later mean exceeds the trough by more than 3 standard errors) to a plateau.
The plateau is the mean over the last `--plateau` seconds with a batch-means standard error
(10 batches), and the run is called stationary there if its two halves agree within 3 errors.
Smoothing: centred moving average over `--smooth` seconds (0.5 s for the trough). A run whose
plateau is under 5 % of its peak "settles to rest". Standard library only.
  usage: scripts/settling_stages.py RUN_DIR [--smooth 0.1] [--plateau 2.0] [--every 0.25]
"""
import argparse
import csv
import math
import os


def batch_mean(v, batches=10):
    k = len(v) // batches
    if k == 0:
        return float("nan"), float("nan")
    bm = [sum(v[i * k:(i + 1) * k]) / k for i in range(batches)]
    m = sum(bm) / batches
    se = math.sqrt(sum((x - m) ** 2 for x in bm) / (batches - 1) / batches)
    return m, se


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run_dir")
    ap.add_argument("--smooth", type=float, default=0.1, help="moving-average window (s)")
    ap.add_argument("--plateau", type=float, default=2.0, help="final window for the plateau (s)")
    ap.add_argument("--every", type=float, default=0.25, help="print the smoothed curve every (s)")
    a = ap.parse_args()
    rows = list(csv.DictReader(open(os.path.join(a.run_dir, "timeseries.csv"))))
    t = [float(r["time_s"]) for r in rows]
    s = [-float(r["mean_wp_m_s"]) for r in rows]
    n = len(t)
    if n < 20:
        raise SystemExit("too few rows")
    dt = (t[-1] - t[0]) / (n - 1)
    h = max(1, int(round(a.smooth / dt / 2)))
    sm = [sum(s[max(0, i - h):i + h + 1]) / len(s[max(0, i - h):i + h + 1]) for i in range(n)]
    T = t[-1]
    # stage I: first peak = maximum over the first half of the run
    half = [i for i in range(n) if t[i] <= T / 2]
    ip = max(half, key=lambda i: sm[i])
    # stage II: the minimum after the peak of a 0.5 s average (0.1 s leaves the plateau's noise
    # in), within 3 s of the peak and before the plateau window
    h2 = max(1, int(round(0.5 / dt / 2)))
    sm2 = [sum(s[max(0, i - h2):i + h2 + 1]) / len(s[max(0, i - h2):i + h2 + 1]) for i in range(n)]
    after = [i for i in range(ip, n) if t[i] <= min(t[ip] + 3.0, T - a.plateau)] or [ip]
    it = min(after, key=lambda i: sm2[i])
    late = [s[i] for i in range(n) if t[i] >= T - a.plateau]
    m, se = batch_mean(late)
    first = [s[i] for i in range(n) if T - a.plateau <= t[i] < T - a.plateau / 2]
    second = [s[i] for i in range(n) if t[i] >= T - a.plateau / 2]
    m1, se1 = batch_mean(first)
    m2, se2 = batch_mean(second)
    reacc = m - sm2[it]
    print(f"run {a.run_dir}: {n} rows, t = {t[0]:.3f} .. {T:.3f} s, smoothing {2 * h * dt:.3f} s")
    verdict = "yes" if reacc > 3 * se else "no"
    dip = sm[ip] - sm2[it]
    if abs(m) < 0.05 * sm[ip]:
        print(f"settles to rest: the speed peaks at {sm[ip] * 1e3:.1f} mm/s at {t[ip]:.2f} s and falls to "
              f"{m * 1e3:.2f} +- {se * 1e3:.2f} mm/s over the last {a.plateau:g} s (under 5 % of the peak)")
    elif dip < max(0.1 * sm[ip], 3 * se):
        # a dip within 10 % (or within the noise) is no resuspension stage
        print(f"no distinct stages: the speed rises to {sm[ip] * 1e3:.1f} mm/s by {t[ip]:.2f} s and the largest later "
              f"dip is {dip / sm[ip] * 100:.0f} % (stages need > 10 %); plateau {m * 1e3:.1f} +- {se * 1e3:.1f} mm/s "
              f"over the last {a.plateau:g} s")
    else:
        print(f"stage I   (stratified acceleration): 0 -> {t[ip]:.2f} s, settling speed up to {sm[ip] * 1e3:.1f} mm/s")
        print(f"stage II  (resuspension):            {t[ip]:.2f} -> {t[it]:.2f} s, down to {sm2[it] * 1e3:.1f} mm/s "
              f"({dip / sm[ip] * 100:.0f} % below the peak)")
        print(f"stage III (secondary instability):   re-acceleration after {t[it]:.2f} s: {verdict} "
              f"(plateau {m * 1e3:.1f} +- {se * 1e3:.1f} mm/s over the last {a.plateau:g} s, "
              f"{reacc * 1e3:+.1f} mm/s against the trough)")
    # 0.1 mm/s floor: a bed at rest has batch errors of zero
    stat = "yes" if abs(m1 - m2) < max(3 * math.hypot(se1, se2), 1e-4) else "no"
    print(f"plateau stationary (halves {m1 * 1e3:.1f} +- {se1 * 1e3:.1f} and {m2 * 1e3:.1f} +- {se2 * 1e3:.1f} mm/s): {stat}")
    out, nxt = [], 0.0
    for i in range(n):
        if t[i] >= nxt - 1e-9:
            out.append(f"{t[i]:.2f}:{sm[i] * 1e3:.0f}")
            nxt += a.every
    print("smoothed settling speed (s:mm/s) " + " ".join(out))


if __name__ == "__main__":
    main()
