#!/usr/bin/env bash
# Reformats in place, per .clang-format and with clang-format 14 only (see check_format.sh), every
# *.cpp/*.hpp under solver/, driver/, tests/ and bench/, or the files given as arguments.
# ctest Style.ClangFormatClean checks the result (scripts/check_format.sh).
set -euo pipefail
exec "$(dirname "$0")/check_format.sh" --fix "$@"
