#!/usr/bin/env bash
# Rebuilds the full-size curve of docs/results.md from the committed summaries alone (no campaign
# database): each docs/results/runs/<case_id>/summary.json becomes the summary.json of a run folder,
# `study collect` records them in a scratch database, and `query curve` writes the CSV and the plots.
#   scripts/results_from_summaries.sh [BOYCOTT_BIN]
# Writes docs/results/paper_base_full.csv, each group's peak (query peak) to
# docs/results/paper_base_full_peaks.csv, one row per finished run (query runs: its window, error
# basis, correlation times, wall time, core-hours and CPU core-hours) to docs/results/paper_base_full_runs.csv, and
# docs/plots/paper_base_full.{png,pdf}. A committed run that stops short of the end its case now
# asks (raised later) is on neither the curve nor the runs list until a run reaches that end.
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
"$bin" query runs --db "$work/full.db" --study paper_base_full --format csv \
  > "$root/docs/results/paper_base_full_runs.csv"
"$bin" query runs --db "$work/full.db" --study paper_base_full | grep "core-hours"
for ext in png pdf; do
  "$bin" query curve --db "$work/full.db" --study paper_base_full --overlay-paper \
    --plot "$root/docs/plots/paper_base_full.$ext" > /dev/null
done
"$bin" query curve --db "$work/full.db" --study paper_base_full
"$bin" query peak --db "$work/full.db" --study paper_base_full
