#!/usr/bin/env bash
# The repository holds no run outputs (issue 25): output directories (*-out, *.partial-* staging
# sets), particle files (.vtu, .pvtu, .pvd) and summary.json belong under /tmp, never in git.
# The golden expectations (tests/golden/expected) are normalized extracts, not run outputs.
# Usage: tree_clean.sh REPO
set -euo pipefail
cd "${1:?usage: tree_clean.sh REPO}"
if git rev-parse --is-inside-work-tree > /dev/null 2>&1; then
  files=$(git ls-files)
else
  files=$(find . -path ./build -prune -o -type f -print | sed 's|^\./||')
fi
bad=$(printf '%s\n' "$files" | grep -E '(^|/)[^/]*(-out|\.partial-[^/]*)/|\.(vtu|pvtu|pvd)$|(^|/)summary\.json$|(^|/)steps\.csv$|(^|/)modes\.csv$' | grep -v '^tests/golden/expected/' || true)
if [ -n "$bad" ]; then
  echo "tree_clean: run outputs are in the repository (write them under /tmp with -output_dir, then git rm them):"
  printf '%s\n' "$bad" | head -20
  exit 1
fi
echo "ok: no run outputs in the repository"
