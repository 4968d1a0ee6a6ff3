#!/usr/bin/env bash
# A coupled run on 2 ranks stopped by SIGTERM right after its first checkpoint and run again on 2
# ranks ends bitwise equal to the uninterrupted 2-rank run (time series, summary, force budget,
# velocity profile); the same checkpoint resumed on 1 and on 3 ranks runs to the end (another
# decomposition: not bitwise). The 2-rank velocity profile adds up to the run's <<w_p>>, and the
# first step resumed on 1 rank has the cluster index of the 2-rank run's step (its particle
# counts summed over the ranks).
#   parallel_resume.sh BOYCOTT_BIN CASE.toml
set -euo pipefail
bin=$1; case_file=$2
# Open MPI yields the core while it waits only where a job has more ranks than cores (the 3-rank
# run here). Forcing it on for the 2-rank runs made them 25x slower beside two busy processes
# (0.02 s of this case: 44 s against 1.6 s) and the test ran past its timeout.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
# With the force budget on: its histograms are summed over ranks for each checkpoint (a sum inside
# rank 0's writer once left rank 1 waiting in the next step, both for ever).
# The first checkpoint early (0.02 s): the stop lands with most of the run ahead even on a fast
# machine (the whole 0.2 s takes ~1 s quiet). The resumes on 1 and 3 ranks go on to 0.08 s only:
# 3 ranks on 2 cores beside two busy processes run this case ~50x slower than on a quiet machine.
sets=(--set time.end=0.2 --set time.average_from=0.04 --set time.checkpoint_every=0.02 --set output.force_budget_y=true
      --set output.velocity_profile_y=true)
short_end=0.08
on() { local n=$1; shift; if [ "$n" -eq 1 ]; then "$bin" "$@"; else mpirun -n "$n" "$bin" "$@"; fi; }
on 2 case run "$case_file" --out "$work/ref" "${sets[@]}" > /dev/null
mpirun -n 2 "$bin" case run "$case_file" --out "$work/run" "${sets[@]}" > /dev/null 2> "$work/err.txt" &
pid=$!  # mpirun itself
until compgen -G "$work/run/checkpoints/ckpt_*.h5" > /dev/null; do
  kill -0 "$pid" 2> /dev/null || { echo "the run ended before its first checkpoint"; exit 1; }
  sleep 0.02
done
# To the ranks themselves: Open MPI's mpirun passed a SIGTERM on only ~1 s later (the run had
# gone on from 0.02 s to 0.199 s), which on a fast machine is the end of this run.
pkill -TERM -P "$pid"
wait "$pid" || true
grep -q '"interrupted"' "$work/run/summary.json" || { echo "not interrupted:"; cat "$work/err.txt"; exit 1; }
cp "$work/run/summary.json" "$work/stopped_summary.json"
cp -r "$work/run" "$work/run1"
cp -r "$work/run" "$work/run3"
on 2 case run "$case_file" --out "$work/run" "${sets[@]}" > /dev/null 2>> "$work/err.txt"
on 1 case run "$case_file" --out "$work/run1" "${sets[@]}" --set time.end=$short_end > /dev/null 2>> "$work/err.txt"
on 3 case run "$case_file" --out "$work/run3" "${sets[@]}" --set time.end=$short_end > /dev/null 2>> "$work/err.txt"
python3 - "$work" "$short_end" <<'PY'
import csv
import json, sys, pathlib
w = pathlib.Path(sys.argv[1])
ref = json.load(open(w / "ref" / "summary.json"))
run = json.load(open(w / "run" / "summary.json"))
assert run["resumed_from_checkpoint"] and run["mpi_ranks"] == 2, run
for k in ("mean_settling_velocity_m_s", "settling_velocity_stderr_m_s", "cfd_steps", "dem_steps",
          "mean_fluid_velocity_m_s", "max_abs_slurry_velocity_m_s", "simulated_time_s", "particle_count"):
    assert ref[k] == run[k], (k, ref[k], run[k])
assert (w / "ref" / "timeseries.csv").read_text() == (w / "run" / "timeseries.csv").read_text(), "time series differ"
assert (w / "ref" / "force_budget_y.csv").read_text() == (w / "run" / "force_budget_y.csv").read_text(), "budgets differ"
assert (w / "ref" / "velocity_profile_y.csv").read_text() == (w / "run" / "velocity_profile_y.csv").read_text(), "profiles differ"
for k in ("cluster_index_mean", "cluster_index_samples"):
    assert ref[k] == run[k], (k, ref[k], run[k])
# The bands add up to the whole: flux shares to 1, sample shares to 1 and (pdf_y's bins)
# pdf_y's density times the bin width, the bands' w_p weighted by their shares to <<w_p>>.
rows = list(csv.DictReader(open(w / "ref" / "velocity_profile_y.csv")))
pdf = list(csv.DictReader(open(w / "ref" / "pdf_y.csv")))
assert len(rows) == len(pdf), (len(rows), len(pdf))
width = float(pdf[1]["y_m"]) - float(pdf[0]["y_m"])
for r, p in zip(rows, pdf):
    assert abs(float(r["sample_share"]) - float(p["probability_density"]) * width) < 1e-8, (r, p)
shares = [float(r["sample_share"]) for r in rows]
assert abs(sum(shares) - 1) < 1e-8 and abs(sum(float(r["flux_share"]) for r in rows) - 1) < 1e-8, rows
wp = sum(s * float(r["wp_m_s"]) for s, r in zip(shares, rows) if s > 0)
assert abs(wp / ref["mean_settling_velocity_m_s"] - 1) < 1e-7, (wp, ref["mean_settling_velocity_m_s"])
print(f"[ report ] velocity profile: sum of sample share x w_p {wp:.9g} m/s, <<w_p>> {ref['mean_settling_velocity_m_s']:.9g} m/s")
# One step after the resume on 1 rank the particles stand where they stand on 2 (to round-off, far
# below a column's width): the same counts per column, the same index.
stop_t = json.load(open(w / "stopped_summary.json"))["simulated_time_s"]
ref_rows = {round(float(r["time_s"]), 9): r for r in csv.DictReader(open(w / "ref" / "timeseries.csv"))}
first = next(r for r in csv.DictReader(open(w / "run1" / "timeseries.csv")) if float(r["time_s"]) > stop_t + 1e-9)
same = ref_rows[round(float(first["time_s"]), 9)]
assert abs(float(first["cluster_index"]) - float(same["cluster_index"])) < 1e-9, (first, same)
print(f"[ report ] cluster index at {first['time_s']} s: {first['cluster_index']} on 1 rank, {same['cluster_index']} on 2")
short_end = float(sys.argv[2])
for name, ranks in (("run1", 1), ("run3", 3)):
    s = json.load(open(w / name / "summary.json"))
    assert s["status"] == "completed" and s["mpi_ranks"] == ranks and s["resumed_from_checkpoint"], s
    assert abs(s["simulated_time_s"] - short_end) < 1e-9 and s["particle_count"] == ref["particle_count"], s
    print(f"[ report ] resumed on {ranks} rank(s) to {short_end:g} s: <<w_p>> {s['mean_settling_velocity_m_s']:.6g} m/s")
t = sum(1 for _ in open(w / "ref" / "timeseries.csv")) - 1
print(f"[ report ] stopped on 2 ranks and resumed on 2: time series ({t} rows) and summary identical")
PY
