#!/usr/bin/env python3
"""How many DEM sub-steps could each particle of a checkpoint skip: the time until it could first
touch another particle or a wall, from its gaps and relative speeds there (issue 63, lever 1).

    bench/substep_reach.py RUN_DIR/checkpoints/ckpt_N.h5 [--dt-dem 2e-5] [--accel 20]

A pair whose surfaces are g apart and whose velocities differ by s cannot touch before
t = (sqrt(s^2 + 2 a g) - s) / a, where a bounds how fast their relative velocity can change
(m/s^2): gravity less buoyancy and the drag's pull for each of the two (by default 20, about
twice (g (1 - rho_f / rho_p) + |u_f - v| / tau_p) for 0.6 mm sand in water slipping at 0.2 m/s).
A wall is at rest and one particle moves: a / 2. A particle's reach time is its smallest over its
neighbours and the two walls at y = 0 and W (the inclined channel is periodic in x and z); it is
free for k sub-steps when that time exceeds k dt_dem.

It also prices a second, thinner list inside the neighbour list (a "near list" of the pairs
whose gap is below m < the skin S, filtered from the list and renewed when a particle could have
moved m / 2): the contact search tests the near pairs every step and all list pairs once per
renewal (DemSystem's near pairs, m = S / 3; bench_dem prints their count and renewals). A list lasts --list-steps DEM steps (a rebuild when a particle could have moved S / 2);
over these few steps the particles move ballistically, so a near list lasts about m / S of that.
Pair tests per step against the list's: near / list + (list / near list's life) / list.

Needs python3-h5py, -numpy and -scipy (Debian packages); reads the 38-array checkpoints of
DemSystem (particle_store.hpp order).
"""
import argparse
import json

import h5py
import numpy as np
from scipy.spatial import cKDTree


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("checkpoint")
    ap.add_argument("--dt-dem", type=float, default=None, help="s (default: the case's time.dt_dem)")
    ap.add_argument("--accel", type=float, default=20.0, help="bound on the relative acceleration, m/s^2")
    ap.add_argument("--list-steps", type=float, default=15.0,
                    help="DEM steps a neighbour list lasts (the full case: 15-18, summary.json)")
    a = ap.parse_args()
    with h5py.File(a.checkpoint, "r") as f:
        case = json.loads(bytes(np.asarray(f["case_json"][()], dtype=np.uint8)).decode())  # stored as integers
        arr = [np.asarray(f[f"dem.array{k:02d}"][()]) for k in range(6)]
        radius = np.asarray(f["dem.array15"][()])
        time_s = float(np.asarray(f["run.time_s"][()]).ravel()[0])
    dom = case["domain"]
    L = np.array([dom["length_x"], dom["width_y"], dom["height_z"]])
    dt = a.dt_dem or case["time"]["dt_dem"]
    skin = case["numerics"]["neighbor_skin"]
    x = np.stack(arr[0:3], axis=1)
    v = np.stack(arr[3:6], axis=1)
    R = radius.max()
    # The longest reach a fluid step of 50 sub-steps could need, with margin: 2 |v|max t + a t^2.
    horizon = 50 * dt
    reach = max(2 * np.abs(v).max() * np.sqrt(3) * horizon + a.accel * horizon**2 + 1e-4, skin)
    box = np.array([L[0], 1e3, L[2]])  # y is walled: a box far larger than the gap
    p = x.copy()
    p[:, 0] %= L[0]
    p[:, 2] %= L[2]
    tree = cKDTree(p, boxsize=box)
    pairs = tree.query_pairs(2 * R + reach, output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    d = p[i] - p[j]
    d[:, 0] -= L[0] * np.round(d[:, 0] / L[0])
    d[:, 2] -= L[2] * np.round(d[:, 2] / L[2])
    gap = np.linalg.norm(d, axis=1) - radius[i] - radius[j]
    s = np.linalg.norm(v[i] - v[j], axis=1)
    t_pair = np.where(gap <= 0, 0.0, (np.sqrt(s * s + 2 * a.accel * np.maximum(gap, 0)) - s) / a.accel)
    n = len(p)
    t = np.full(n, np.inf)
    np.minimum.at(t, i, t_pair)
    np.minimum.at(t, j, t_pair)
    aw = a.accel / 2
    for g, sp in ((p[:, 1] - radius, np.abs(v[:, 1])), (L[1] - p[:, 1] - radius, np.abs(v[:, 1]))):
        tw = np.where(g <= 0, 0.0, (np.sqrt(sp * sp + 2 * aw * np.maximum(g, 0)) - sp) / aw)
        t = np.minimum(t, tw)
    t = np.minimum(t, horizon * 1.0001)  # beyond the search's horizon: free for the whole step
    print(f"{a.checkpoint}: t = {time_s:.3f} s, {n} particles, {len(pairs)} pairs within {1e3 * (2 * R + reach):.2f} mm, "
          f"dt_dem {dt * 1e6:g} us, relative acceleration bound {a.accel:g} m/s^2")
    print(f"touching now (a particle or a wall): {np.mean(t == 0):.3f}")
    half = np.mean(p[:, 2] < L[2] / 2)
    print(f"share of the particles in the lower z half (where 2 ranks split the slabs): {half:.3f}")
    print("sub-steps k | share free for k | share of particle-sub-steps a chunk of k could skip")
    for k in (1, 2, 5, 10, 25, 50):
        free = np.mean(t > k * dt)
        print(f"{k:11d} | {free:16.3f} | {free * (1 - 1 / k):.3f}")
    listed = np.count_nonzero(gap < skin)
    print(f"neighbour list (skin {skin * 1e3:g} mm): {listed / n:.2f} pairs per particle, "
          f"{np.count_nonzero(gap < 0) / n:.2f} of them in contact; a list lasts {a.list_steps:g} steps")
    print("near skin (mm) | near pairs per particle | its life (steps) | pair tests per step / the list's")
    for m in (0.025, 0.05, 0.1, 0.15, 0.2):
        near = np.count_nonzero(gap < m * 1e-3)
        life = max(1.0, a.list_steps * m * 1e-3 / skin)
        print(f"{m:14g} | {near / n:23.2f} | {life:16.1f} | {near / listed + 1 / life:.3f}")


if __name__ == "__main__":
    main()
