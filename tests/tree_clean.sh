#!/usr/bin/env bash
# The repository holds no run outputs, and no two files share a name (issue 25): output directories (*-out, *.partial-* staging
# sets), particle files (.vtu, .pvtu, .pvd), summary.json and scene.yaml belong under /tmp, never in git.
# The golden expectations (tests/golden/expected) are normalized extracts, not run outputs.
# The bad-input corpus (tests/bad_input) holds hand-made damaged particle files, not run outputs.
# Usage: tree_clean.sh REPO
set -euo pipefail
cd "${1:?usage: tree_clean.sh REPO}"
if git rev-parse --is-inside-work-tree > /dev/null 2>&1; then
  files=$(git ls-files | sort -u) # unmerged paths are listed once per stage
else
  files=$(find . -path ./build -prune -o -type f -print | sed 's|^\./||')
fi
bad=$(printf '%s\n' "$files" | grep -E '(^|/)[^/]*(-out|\.partial-[^/]*)/|\.(vtu|pvtu|pvd)$|(^|/)(summary\.json|scene\.yaml)$|(^|/)steps\.csv$|(^|/)modes\.csv$' | grep -v '^tests/golden/expected/' | grep -v '^tests/bad_input/' || true)
if [ -n "$bad" ]; then
  echo "tree_clean: run outputs are in the repository (write them under /tmp with -output_dir, then git rm them):"
  printf '%s\n' "$bad" | head -20
  exit 1
fi
# every file a newcomer looks for by name has a name of its own: sources, headers, scripts,
# examples and docs (the per-case data of tests/golden/expected and tests/bad_input, and CMake's
# fixed CMakeLists.txt, are exempt)
dups=$(printf '%s\n' "$files" | grep -v '^tests/golden/expected/\|^tests/bad_input/.*\.yaml$\|^tests/bad_input/.*/\|CMakeLists.txt$' | xargs -n1 basename | sort | uniq -d)
if [ -n "$dups" ]; then
  echo "tree_clean: file names used twice (a newcomer finds a concept by its file name; rename one):"
  for d in $dups; do printf '%s\n' "$files" | grep "/$d\$\|^$d\$" | sed 's/^/  /'; done
  exit 1
fi
echo "ok: no run outputs in the repository; every source, script, example and doc has a name of its own"
