#!/usr/bin/env python3
"""A stand-in for `boycott case run CASE --out DIR` that obeys its contract (README.md,
"Running a case"), so the study driver's resume, retry and signal logic is tested against real processes.

It advances a simulated clock in steps of 0.1 s up to time.end (sleeping FAKE_STEP_WALL_S per
step), checkpoints its state to DIR/checkpoint.json every step, appends DIR/timeseries.csv, and
writes DIR/summary.json at the end with the real solver's keys and statuses (core/run_status.hpp:
"completed" at the end, "interrupted" when stopped; test_driver_faults checks them against the
real solver). The result depends on the parameters only (never on how often it was interrupted):
<<w_p>> = -0.01 (1 + 0.5 sin(theta)) * (viscosity/1e-3)^-0.1 m/s; with FAKE_PEAK_DEG set,
-0.01 (1 + 0.5 exp(-((theta - FAKE_PEAK_DEG)/15)^2/2)) * (viscosity/1e-3)^-0.1 m/s (a peak inside).
Exit 75 on SIGTERM/SIGINT after a checkpoint; exit 3 once per run folder when seed == 13 and
FAKE_FAIL_SEED13 is set (a retried failure); exit 3 always when seed == 14 (a failure for good).
Exit 74 (a storage error: "No space left on device") on the first FAKE_STORAGE_FAILS runs in a
run folder before any step, or on every run when FAKE_STORAGE_FAILS = "always".
"""
import json, math, os, signal, sys, time
import tomllib

def write_atomic(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)

def main():
    stop = {"sig": 0}
    def on_stop(sig, frame):
        stop["sig"] = sig
    signal.signal(signal.SIGTERM, on_stop)
    signal.signal(signal.SIGINT, on_stop)
    args = sys.argv[1:]
    if args[:2] != ["case", "run"] or "--out" not in args:
        print("usage: fake_solver.py case run CASE --out DIR", file=sys.stderr)
        return 2
    case_file = args[2]
    out = args[args.index("--out") + 1]
    try:
        # As the real solver: a *.json case is the canonical JSON a study writes (case.json).
        with open(case_file, "rb") as f:
            p = json.load(f) if case_file.endswith(".json") else tomllib.load(f)
    except Exception as e:
        print(f"error: cannot read case file '{case_file}': {e}", file=sys.stderr)
        return 2
    os.makedirs(out, exist_ok=True)

    seed = p.get("seed", 1)
    if seed == 14:
        print("error: the run became unphysical: alpha_f = -0.2 in cell (3, 1, 7)", file=sys.stderr)
        return 3
    marker = os.path.join(out, "failed_once")
    if seed == 13 and os.environ.get("FAKE_FAIL_SEED13") and not os.path.exists(marker):
        open(marker, "w").close()
        print("error: the run became unphysical: NaN in the pressure", file=sys.stderr)
        return 3

    fails = os.environ.get("FAKE_STORAGE_FAILS")
    if fails:
        counter = os.path.join(out, "storage_failures")
        n = int(open(counter).read()) if os.path.exists(counter) else 0
        if fails == "always" or n < int(fails):
            with open(counter, "w") as f:
                f.write(str(n + 1))
            print(f"error: cannot write {out}/checkpoint.json.tmp: No space left on device", file=sys.stderr)
            return 74

    end = p["time"]["end"]
    angle = p["gravity"]["angle_deg"]
    visc = p["fluid"]["viscosity"]
    count = p["particles"]["count"]
    step_wall = float(os.environ.get("FAKE_STEP_WALL_S", "0.01"))
    ckpt = os.path.join(out, "checkpoint.json")
    state = {"step": 0, "sum": 0.0, "sum2": 0.0, "n": 0}
    if os.path.exists(ckpt):
        try:
            with open(ckpt) as f:
                state = json.load(f)
        except Exception as e:
            print(f"error: checkpoint '{ckpt}' is unusable: {e}", file=sys.stderr)
            return 4
    nsteps = int(round(end / 0.1))
    w_mean = -0.01 * (1 + 0.5 * math.sin(math.radians(angle))) * (visc / 1e-3) ** -0.1
    if os.environ.get("FAKE_PEAK_DEG"):
        # A curve with its peak inside the range, for [refine]: |w| largest at FAKE_PEAK_DEG.
        peak = float(os.environ["FAKE_PEAK_DEG"])
        w_mean = -0.01 * (1 + 0.5 * math.exp(-((angle - peak) / 15.0) ** 2 / 2)) * (visc / 1e-3) ** -0.1
    # The timeseries is rewritten from the checkpointed step, so a resumed run leaves the same file.
    ts = os.path.join(out, "timeseries.csv")
    lines = ["time_s,w_p_m_s\n"]
    if os.path.exists(ts):
        with open(ts) as f:
            lines = f.readlines()[: state["step"] + 1]
    t0 = time.time()
    # As the real solver: CPU time over all attempts, carried in the checkpoint; unknown (null)
    # after a checkpoint that has none.
    cpu0, cpu_before = time.process_time(), state.get("cpu_time_s", None if state["step"] > 0 else 0.0)

    def cpu_total():
        return None if cpu_before is None else cpu_before + time.process_time() - cpu0

    def summary(status):
        n = max(state["n"], 1)
        mean = state["sum"] / n
        var = max(state["sum2"] / n - mean * mean, 0.0)
        return {
            "scene": p.get("scene", "inclined_settling"),
            "case_id": os.path.basename(os.path.normpath(out)),
            "status": status,
            "mean_settling_velocity_m_s": mean,
            "settling_velocity_stderr_m_s": math.sqrt(var / n),
            "simulated_time_s": state["step"] * 0.1,
            "wall_time_s": time.time() - t0,
            "cpu_time_s": cpu_total(),
            "particle_steps": count * state["step"] * 50,
            "models": {"drag": p["forces"]["drag"]},
            "mean_fluid_velocity_m_s": -0.1 * mean,
            "mean_slurry_velocity_m_s": 0.0,
        }

    while state["step"] < nsteps:
        if stop["sig"]:
            # As the real solver: the checkpoint below was written after the last completed step.
            write_atomic(os.path.join(out, "summary.json"), json.dumps(summary("interrupted"), indent=1))
            return 75
        k = state["step"] + 1
        w = w_mean * (1 + 0.1 * math.sin(1.7 * k))
        state["sum"] += w
        state["sum2"] += w * w
        state["n"] += 1
        state["step"] = k
        if cpu_before is not None:
            state["cpu_time_s"] = cpu_total()
        lines.append(f"{k * 0.1:.6f},{w:.9e}\n")
        write_atomic(ts, "".join(lines))
        write_atomic(ckpt, json.dumps(state))
        time.sleep(step_wall)
    write_atomic(os.path.join(out, "summary.json"), json.dumps(summary("completed"), indent=1))
    return 0

if __name__ == "__main__":
    sys.exit(main())
