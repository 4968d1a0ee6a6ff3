#!/usr/bin/env python3
"""Where the particles sit across the gap, and which forces hold them there.

  scripts/gap_profile.py [--budget] [--profile] RUN_DIR [RUN_DIR ...]
  scripts/gap_profile.py --layers RUN_DIR [RUN_DIR ...]

Averages pdf_y.csv (with --budget force_budget_y.csv, with --profile velocity_profile_y.csv) of the
runs given (replicas of one
case), prints the profile as density over its mean from wall to wall, and two numbers:
  interior_cv   the coefficient of variation (rms / mean) of the density over the bands whose
                centre lies at least 0.75 mm from both walls: 0 for a flat interior; sheets that
                the grid imprints raise it, and a grid artefact moves when the grid does;
  wall_layer    the mean density of the bands from the contact distance d/2 out to d/2 + 0.45 mm,
                both walls, over the mean density (the paper's Fig. 12(a): a rise at both walls).
With --budget, the mean y-force per particle of every term by band, over the buoyant weight,
and the band's mean particle and shear Reynolds numbers (the lift law's inputs). With --profile,
the band's mean w_p, the w_f its particles see and their slip (mm/s), and its share of the flux (%).
With --layers (runs that wrote all three files), per wall (y = 0 and y = W, each measured from its
own wall) the layers next to it, as the mean over the runs and the standard error of that mean:
  touching    density of the bands whose centre lies within 0.075 mm of d/2 (the particles
              touching the wall), over the uniform density a centre can have, 1 / (W - d);
  next        the same from d/2 + 0.075 mm to d/2 + 0.45 mm (the paper's Fig. 12(a): a rise at the
              wall; at full size the product holds 0.70-0.80 there);
  w_p, w_f    the particles' mean velocity along the channel and the fluid's they see in `next`
              (mm/s, + upward);
  v_f seen    the transverse fluid velocity the particles see from d/2 + 0.075 to d/2 + 1.2 mm
              (mm/s, + away from this wall; their own transverse velocity averages to ~0);
  drag, pressure, lift, contacts, net: the mean transverse forces from d/2 + 0.075 to d/2 + 0.6 mm
              in % of the buoyant weight, + away from this wall (net = m dv/dt).
"""
import json
import csv
import statistics
import sys
from pathlib import Path


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def mean_columns(dirs, name):
    tables = [read(Path(d) / name) for d in dirs]
    cols = [c for c in tables[0][0].keys()]
    out = []
    for b in range(len(tables[0])):
        out.append({c: statistics.fmean(float(t[b][c]) for t in tables) for c in cols})
    return out


def layers(dirs):
    """The layers next to each wall (see the module's doc), over the runs in dirs."""
    per_wall = {"y = 0": [], "y = W": []}
    for d in dirs:
        radius_mm = json.loads((Path(d) / "params.json").read_text())["particles"]["diameter"] * 500
        pdf = read(Path(d) / "pdf_y.csv")
        prof = read(Path(d) / "velocity_profile_y.csv")
        bud = read(Path(d) / "force_budget_y.csv")
        y_mm = [float(r["y_m"]) * 1e3 for r in pdf]
        width_mm = 2 * y_mm[0] * len(y_mm)
        uniform = 1e3 / (width_mm - 2 * radius_mm)  # 1/m
        for wall, sign in (("y = 0", 1), ("y = W", -1)):
            dist = [yy if sign > 0 else width_mm - yy for yy in y_mm]

            def mean_in(lo, hi, values):
                sel = [v for x, v in zip(dist, values) if radius_mm + lo <= x < radius_mm + hi and v == v]
                return statistics.fmean(sel) if sel else float("nan")

            dens = [float(r["probability_density"]) / uniform for r in pdf]
            row = {
                "touching": mean_in(-0.075, 0.075, dens),
                "next": mean_in(0.075, 0.45, dens),
                "w_p": mean_in(0.075, 0.45, [float(r["wp_m_s"]) * 1e3 for r in prof]),
                "w_f": mean_in(0.075, 0.45, [float(r["wf_seen_m_s"]) * 1e3 for r in prof]),
                "v_f seen": mean_in(0.075, 1.2, [sign * float(r["vf_seen_m_s"]) * 1e3 for r in prof]),
            }
            for t in ("drag", "pressure_gradient", "lift", "particle_contacts", "net"):
                row[t] = mean_in(0.075, 0.6, [sign * float(r[t + "_per_weight"]) * 100 for r in bud])
            per_wall[wall].append(row)
    n = len(dirs)
    print(f"runs {n}; mean and standard error over the runs")
    for wall, rows in per_wall.items():
        parts = []
        for k in rows[0]:
            vals = [r[k] for r in rows]
            err = f" ± {statistics.stdev(vals) / n ** 0.5:.2f}" if n > 1 else ""
            parts.append(f"{k} {statistics.fmean(vals):.2f}{err}")
        print(f"{wall}: " + "; ".join(parts))


def main(argv):
    if "--layers" in argv:
        dirs = [a for a in argv if a != "--layers"]
        if not dirs:
            sys.exit(__doc__)
        layers(dirs)
        return
    budget = "--budget" in argv
    profile = "--profile" in argv
    dirs = [a for a in argv if a not in ("--budget", "--profile")]
    if not dirs:
        sys.exit(__doc__)
    pdf = mean_columns(dirs, "pdf_y.csv")
    y = [r["y_m"] for r in pdf]
    dens = [r["probability_density"] for r in pdf]
    width = 2 * y[0] * len(y)  # bins tile [0, W)
    rel = [d * width for d in dens]  # density over its mean
    radius = 0.3e-3
    inner = [r for yy, r in zip(y, rel) if 0.75e-3 <= yy <= width - 0.75e-3]
    cv = statistics.pstdev(inner) / statistics.fmean(inner)
    layer = [r for yy, r in zip(y, rel) if radius <= yy <= radius + 0.45e-3 or width - radius - 0.45e-3 <= yy <= width - radius]
    print(f"runs {len(dirs)}; W = {width * 1e3:.3g} mm; interior_cv {cv:.3f}; wall_layer {statistics.fmean(layer):.2f}")
    print("y_mm    " + " ".join(f"{yy * 1e3:5.2f}" for yy in y))
    print("density " + " ".join(f"{r:5.2f}" for r in rel))
    if budget:
        b = mean_columns(dirs, "force_budget_y.csv")
        terms = [c[: -len("_per_weight")] for c in b[0] if c.endswith("_per_weight")]
        for t in terms:
            print(f"{t[:8]:8s}" + " ".join(f"{r[t + '_per_weight'] * 100:+5.1f}" for r in b))
        print("(forces in % of the buoyant weight, + toward the far wall)")
        if "re_p" in b[0]:
            for t in ("re_p", "re_w"):
                print(f"{t:8s}" + " ".join(f"{r[t]:5.1f}" for r in b))
    if profile:
        v = mean_columns(dirs, "velocity_profile_y.csv")
        for t, name in (("wp_m_s", "w_p"), ("wf_seen_m_s", "w_f seen"), ("slip_w_m_s", "slip")):
            print(f"{name[:8]:8s}" + " ".join(f"{r[t] * 1e3:5.0f}" for r in v))
        print("flux %  " + " ".join(f"{r['flux_share'] * 100:5.1f}" for r in v))
        print("(velocities in mm/s along the channel; the flux shares add up to 100)")


if __name__ == "__main__":
    main(sys.argv[1:])
