#!/usr/bin/env bash
# Configures and builds into build/ (Release). Usage: scripts/build.sh [extra cmake args]
# BOYCOTT_BUILD_TARGET=boycott builds the program alone (the main job: no tests).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release "$@" > "$root/build.log" 2>&1 || { cat "$root/build.log"; exit 1; }
target=(${BOYCOTT_BUILD_TARGET:+--target "$BOYCOTT_BUILD_TARGET"})
cmake --build "$root/build" -j "$(nproc)" "${target[@]}" 2>&1 | grep -E "error|warning: unused|Error" || true
cmake --build "$root/build" -j "$(nproc)" "${target[@]}" > /dev/null
