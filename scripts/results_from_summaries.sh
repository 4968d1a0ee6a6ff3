#!/usr/bin/env bash
# Rebuilds the full-size curve of docs/results.md from the committed summaries alone (no campaign
# database): each docs/results/runs/<case_id>/summary.json becomes the summary.json of a run folder,
# `study collect` records them in a scratch database, and `query curve` writes the CSV and the plots.
#   scripts/results_from_summaries.sh [BOYCOTT_BIN]
# Writes docs/results/paper_base_full.csv, each group's peak (query peak) to
# docs/results/paper_base_full_peaks.csv, one row per committed run (its window, error basis,
# correlation times, wall time and core-hours: wall time x ranks) to
# docs/results/paper_base_full_runs.csv, and docs/plots/paper_base_full.{png,pdf}.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$root/build/driver/boycott}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for f in "$root"/docs/results/runs/*/summary.json; do
  id=$(basename "$(dirname "$f")")
  mkdir -p "$work/full.db.runs/$id"
  cp "$f" "$work/full.db.runs/$id/summary.json"
done
"$bin" study collect "$root/studies/paper_base_full.toml" --db "$work/full.db" > /dev/null
"$bin" query curve --db "$work/full.db" --study paper_base_full --format csv > "$root/docs/results/paper_base_full.csv"
"$bin" query peak --db "$work/full.db" --study paper_base_full --format csv \
  > "$root/docs/results/paper_base_full_peaks.csv"
"$bin" study status "$root/studies/paper_base_full.toml" --db "$work/full.db" --format csv > "$work/status.csv"
python3 - "$root/docs/results" "$work/status.csv" <<'PY'
import csv, glob, json, os, sys
results = sys.argv[1]
cases = {r["case"]: r for r in csv.DictReader(open(sys.argv[2]))}
cols = ["case_id", "group", "angle_deg", "n_particles", "end_s", "average_from_s",
        "mean_settling_velocity_m_s", "error_m_s", "error_method", "error_dof", "correlation_time_s",
        "window_correlation_times", "wall_time_s", "mpi_ranks", "core_hours"]
rows = []
for f in sorted(glob.glob(os.path.join(results, "runs", "*", "summary.json"))):
    s = json.load(open(f))
    c = cases[s["case_id"]]
    rows.append({"case_id": s["case_id"], "group": c["group"], "angle_deg": c["angle_deg"],
                 "n_particles": s.get("particle_count"),
                 "end_s": round(s["simulated_time_s"], 6), "average_from_s": s.get("average_from_s"),
                 "mean_settling_velocity_m_s": s.get("mean_settling_velocity_m_s"),
                 "error_m_s": s.get("settling_velocity_error_m_s"),
                 "error_method": s.get("settling_velocity_error_method"),
                 "error_dof": s.get("settling_velocity_error_dof"),
                 "correlation_time_s": s.get("settling_velocity_correlation_time_s"),
                 "window_correlation_times": s.get("settling_velocity_window_correlation_times"),
                 "wall_time_s": s.get("wall_time_s"), "mpi_ranks": s.get("mpi_ranks"),
                 "core_hours": round(s["wall_time_s"] * s.get("mpi_ranks", 1) / 3600.0, 3)})
rows.sort(key=lambda r: (r["group"], float(r["angle_deg"] or 0)))
with open(os.path.join(results, "paper_base_full_runs.csv"), "w", newline="") as out:
    w = csv.DictWriter(out, fieldnames=cols)
    w.writeheader()
    w.writerows(rows)
print(f"{len(rows)} committed runs, {sum(r['core_hours'] for r in rows):.1f} core-hours (wall time x ranks)")
PY
for ext in png pdf; do
  "$bin" query curve --db "$work/full.db" --study paper_base_full --overlay-paper \
    --plot "$root/docs/plots/paper_base_full.$ext" > /dev/null
done
"$bin" query curve --db "$work/full.db" --study paper_base_full
"$bin" query peak --db "$work/full.db" --study paper_base_full
