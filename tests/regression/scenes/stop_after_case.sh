#!/usr/bin/env bash
# `case run --stop-after S`: after S wall seconds the run checkpoints and stops as on SIGTERM
# (exit 75, summary "interrupted", a checkpoint kept), and the same command resumes it from that
# checkpoint. The smoke case run to 100 s of simulated time takes tens of minutes on this machine,
# so neither 2 s run can finish on any machine: nothing here depends on how fast it runs.
#   stop_after_case.sh BOYCOTT_BIN CASE.toml
set -uo pipefail
bin=$1; case_file=$2
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
sets=(--set time.end=100 --set time.average_from=0.01 --set time.checkpoint_every=50)
for attempt in 1 2; do
  "$bin" case run "$case_file" --out "$work/run" "${sets[@]}" --stop-after 2 --quiet > /dev/null 2> "$work/err$attempt.txt"
  rc=$?
  [ "$rc" -eq 75 ] || fail "attempt $attempt exited $rc, not 75: $(cat "$work/err$attempt.txt")"
  grep -q '"status": "interrupted"' "$work/run/summary.json" || fail "attempt $attempt: summary not interrupted"
  compgen -G "$work/run/checkpoints/ckpt_*.h5" > /dev/null || fail "attempt $attempt left no checkpoint"
done
grep -q '"resumed_from_checkpoint": true' "$work/run/summary.json" || fail "the second attempt did not resume"
"$bin" case run "$case_file" --out "$work/bad" --stop-after 0 > /dev/null 2>&1
rc=$?
[ "$rc" -eq 2 ] || fail "--stop-after 0 exited $rc, not 2"
echo "[ report ] stopped twice by --stop-after 2 (exit 75, checkpointed), the second attempt resumed"
