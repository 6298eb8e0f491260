#!/usr/bin/env bash
# No function in src/ or models/ runs past 80 lines (docs/build.md, the test table): a long
# function is split into named steps. A function is counted from its opening brace in column 0
# to its closing brace in column 0, as clang-format lays them out.
# Usage: function_length.sh REPO [LIMIT]
set -euo pipefail
repo=$1 limit=${2:-80}
cd "$repo"
long=$(find src models -name '*.c' | sort | xargs awk -v LIM="$limit" '
  /^[A-Za-z].*\)$/ { sig = $0; sigline = FNR }
  /^\{/ { start = FNR; name = sig; sub(/\(.*/, "", name); n = split(name, a, /[ *]+/); name = a[n] }
  /^\}/ { if (start && FNR - start + 1 > LIM) printf "%s:%d %s() has %d lines\n", FILENAME, sigline, name, FNR - start + 1; start = 0 }')
if [[ -n $long ]]; then
  echo "function_length: over $limit lines (split into named steps):"
  echo "$long"
  exit 1
fi
echo "ok: no function in src/ or models/ over $limit lines"
