#!/usr/bin/env bash
# Checks that every *.cpp/*.hpp under solver/, driver/, tests/ and bench/ is formatted per
# .clang-format, with clang-format 14 only (Debian bookworm's clang-format-14; other major versions
# format some constructs differently, so the check would flip with the tool). Prints each file that
# is not formatted and their count; exit status 1 if any (ctest Style.ClangFormatClean).
#   scripts/check_format.sh                 check all files
#   scripts/check_format.sh --fix [FILE...] reformat in place (what scripts/format.sh runs)
# CLANG_FORMAT=/path/to/clang-format picks another binary; it must still say version 14.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

fix=0
if [ "${1:-}" = "--fix" ]; then fix=1; shift; fi

is_14() { "$1" --version 2>/dev/null | grep -Eq 'clang-format version 14\.'; }
cf=""
cands=(clang-format-14 clang-format)
if [ -n "${CLANG_FORMAT:-}" ]; then cands=("$CLANG_FORMAT"); fi
for cand in "${cands[@]}"; do
  if command -v "$cand" >/dev/null 2>&1 && is_14 "$cand"; then cf=$cand; break; fi
done
if [ -z "$cf" ]; then
  last=${cands[${#cands[@]}-1]}
  found=$(command -v "$last" >/dev/null 2>&1 && "$last" --version 2>/dev/null | head -1 || echo none)
  echo "check_format: clang-format 14 not found (${cands[*]}; $last says: $found)." >&2
  echo "check_format: install the Debian package clang-format-14" \
       "(apt-get install clang-format-14, or scripts/install_deps.sh)." >&2
  exit 2
fi
version=$("$cf" --version | grep -Eo 'version [0-9.]+' | head -1)

if [ $# -gt 0 ]; then
  # relative to the caller's directory; only C++ sources and headers (clang-format would also
  # "format" a CMakeLists.txt or a script named here, and break it)
  files=()
  for f in "$@"; do
    case "$f" in
      *.cpp | *.hpp | *.h | *.cc) files+=("$f") ;;
      *) echo "check_format: skipping $f (not a C++ file)" >&2 ;;
    esac
  done
else
  cd "$root"
  mapfile -t files < <(find solver driver tests bench -type f \( -name '*.cpp' -o -name '*.hpp' \) |
                       LC_ALL=C sort)
fi
if [ ${#files[@]} -eq 0 ]; then echo "check_format: no files" >&2; exit 2; fi

if [ $fix -eq 1 ]; then
  "$cf" --style=file -i "${files[@]}"
  echo "format: ${#files[@]} files formatted with $cf ($version)"
  exit 0
fi

# One run over all files (a run per file takes ~15 times as long); its diagnostics name the files.
rc=0
out=$("$cf" --style=file --dry-run --Werror "${files[@]}" 2>&1) || rc=$?
declare -A count=()
for f in "${files[@]}"; do count[$f]=0; done
while IFS= read -r f; do
  if [ -n "${count[$f]+x}" ]; then count[$f]=$((count[$f] + 1)); fi
done < <(grep -Eo '^[^:]+:[0-9]+:[0-9]+: error: code should be clang-formatted' <<<"$out" | cut -d: -f1)
bad=0
for f in "${files[@]}"; do
  if [ "${count[$f]}" -gt 0 ]; then
    echo "$f: ${count[$f]} place(s) not formatted"
    bad=$((bad + 1))
  fi
done
if [ $rc -ne 0 ] && [ $bad -eq 0 ]; then
  echo "check_format: $cf failed (exit $rc):" >&2
  head -20 <<<"$out" >&2
  exit 2
fi
if [ $bad -gt 0 ]; then
  echo "check_format: $bad of ${#files[@]} files not formatted per .clang-format ($cf, $version);" \
       "run scripts/format.sh"
  exit 1
fi
echo "check_format: all ${#files[@]} files formatted per .clang-format ($cf, $version)"
