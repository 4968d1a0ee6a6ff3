#!/usr/bin/env bash
# ctest Fingerprint.SummariesMatchTheCommittedReference: short runs of every scene
# (scripts/fingerprint.sh) against tests/data/fingerprint_reference.txt, within the tolerance
# fingerprint_compare.py derives. A change that moves results fails here until the reference is
# regenerated on purpose (scripts/fingerprint.sh > tests/data/fingerprint_reference.txt).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=$(mktemp)
trap 'rm -f "$out"' EXIT
"$root/scripts/fingerprint.sh" "$1" > "$out"
python3 "$here/fingerprint_compare.py" "$root/tests/data/fingerprint_reference.txt" "$out"
