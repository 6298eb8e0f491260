#!/usr/bin/env bash
# help_version.sh PERILIN SCENE REPO: perilin's help, version and command-line order (issue 28,
# items 4 and 5; docs/scene.md "Help and version"). Checks that
#   1. -help prints perilin's usage first, then perilin's options (every -peri_* option the sources
#      read among them) and the scene keys, and no PETSc section; -h and --help print the same;
#   2. -help petsc prints the same first, and PETSc's and SLEPc's generic list only after it;
#   3. -version and --version print perilin's version (the CMake project version, plus the
#      checkout's `git describe` when REPO is a git checkout), then PETSc's and SLEPc's, equal to
#      pkg-config's and to the PETSC_VERSION_* / SLEPC_VERSION_* macros; exit 0;
#   4. an option before the scene file is an error saying that the scene file comes first;
#   5. summary.json of a tiny run records the same three versions and the command line.
set -u
perilin=$1
scene=$2
repo=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
unset PETSC_OPTIONS SLEPC_OPTIONS
fail=0
bad() { echo "FAIL $*"; fail=1; }

# 1. -help
"$perilin" -help > "$tmp/help" 2>&1 < /dev/null || bad "-help: exit status $?"
[ "$(head -n 1 "$tmp/help")" = "perilin: implicit static and modal peridynamics." ] || bad "-help: first line is not perilin's: $(head -n 1 "$tmp/help")"
sed -n 2p "$tmp/help" | grep -q '^Usage: perilin SCENE.yaml' || bad "-help: second line is not the usage"
opts=$(grep -n '^perilin options:' "$tmp/help" | cut -d: -f1)
keys=$(grep -n '^Scene keys' "$tmp/help" | cut -d: -f1)
if [ -z "$opts" ] || [ -z "$keys" ] || [ "$opts" -ge "$keys" ]; then
  bad "-help: no 'perilin options:' section before the scene keys"
else
  own=$(sed -n "$((opts + 1)),$((keys - 1))p" "$tmp/help")
  read_opts=$(grep -rhoE '"-peri_[a-z_]+"' "$repo/src" "$repo/models" | tr -d '"' | sort -u)
  for o in -quiet -progress -version -output_dir -options_unused_ok $read_opts; do
    grep -qE -- "^  ($o|.*, $o)[ ,]" <<< "$own" || bad "-help: perilin's options do not list $o"
  done
fi
grep -qiE 'Options for all PETSc programs|Petsc Release Version|SLEPc Release Version' "$tmp/help" && bad "-help: prints PETSc's generic help (only -help petsc should)"
for alias in -h --help; do
  "$perilin" $alias > "$tmp/alias" 2>&1 < /dev/null || bad "$alias: exit status $?"
  cmp -s "$tmp/help" "$tmp/alias" || bad "$alias: differs from -help"
done
[ "$fail" -eq 0 ] && echo "ok   -help, -h, --help: perilin's usage, options and keys, no PETSc list"

# 2. -help petsc
f=$fail
"$perilin" -help petsc > "$tmp/petsc" 2>&1 < /dev/null || bad "-help petsc: exit status $?"
n=$(wc -l < "$tmp/help")
head -n "$n" "$tmp/petsc" | cmp -s - "$tmp/help" || bad "-help petsc: does not begin with perilin's help"
tail -n +"$((n + 1))" "$tmp/petsc" | grep -q 'Options for all PETSc programs' || bad "-help petsc: no PETSc options after perilin's help"
tail -n +"$((n + 1))" "$tmp/petsc" | grep -q 'SLEPc Release Version' || bad "-help petsc: no SLEPc banner after perilin's help"
[ "$fail" -eq "$f" ] && echo "ok   -help petsc: perilin's help, then PETSc's and SLEPc's generic list"

# 3. -version
f=$fail
"$perilin" -version > "$tmp/version" 2>&1 < /dev/null || bad "-version: exit status $?"
"$perilin" --version > "$tmp/version2" 2>&1 < /dev/null || bad "--version: exit status $?"
cmp -s "$tmp/version" "$tmp/version2" || bad "--version differs from -version"
[ "$(wc -l < "$tmp/version")" -eq 3 ] || bad "-version: not three lines: $(cat "$tmp/version")"
project=$(sed -n 's/^project(perilin VERSION \([0-9.]*\).*/\1/p' "$repo/CMakeLists.txt")
mine=$(sed -n 's/^perilin //p' "$tmp/version")
case "$mine" in
  "$project" | "$project"+*) ;;
  *) bad "-version: perilin '$mine' is not the project version $project" ;;
esac
if [ -e "$repo/.git" ] && command -v git > /dev/null; then
  describe=$(git -C "$repo" describe --always 2> /dev/null)
  case "$mine" in
    "$project+$describe" | "$project+$describe-dirty") ;;
    *) bad "-version: perilin '$mine' is not $project+$describe[-dirty] (rebuild after a commit)" ;;
  esac
fi
macro() { # the version from the macros of the header $1 with prefix $2
  local h
  h=$(pkg-config --cflags-only-I "$3" | tr ' ' '\n' | sed -n 's/^-I//p' | while read -r d; do [ -f "$d/$1" ] && echo "$d/$1" && break; done)
  [ -n "$h" ] || return
  printf '%s.%s.%s\n' "$(awk -v m="$2_MAJOR" '$1=="#define" && $2==m {print $3}' "$h")" \
    "$(awk -v m="$2_MINOR" '$1=="#define" && $2==m {print $3}' "$h")" \
    "$(awk -v m="$2_SUBMINOR" '$1=="#define" && $2==m {print $3}' "$h")"
}
for lib in "PETSc petscversion.h PETSC_VERSION PETSc" "SLEPc slepcversion.h SLEPC_VERSION slepc"; do
  read -r name header prefix pc <<< "$lib"
  got=$(sed -n "s/^$name //p" "$tmp/version")
  want=$(pkg-config --modversion "$pc")
  [ "$got" = "$want" ] || bad "-version: $name '$got', pkg-config says '$want'"
  want=$(macro "$header" "$prefix" "$pc")
  [ -z "$want" ] || [ "$got" = "$want" ] || bad "-version: $name '$got', $header says '$want'"
done
[ "$fail" -eq "$f" ] && echo "ok   -version, --version: $(tr '\n' ' ' < "$tmp/version")"

# 4. an option before the scene file
f=$fail
"$perilin" -quiet "$scene" > "$tmp/out" 2> "$tmp/err" < /dev/null && bad "-quiet SCENE: exit status 0"
grep -qF "perilin: error: the scene file comes first, then the options: perilin $scene -quiet" "$tmp/err" || bad "-quiet SCENE: $(cat "$tmp/err")"
"$perilin" -grid_spacing 0.1 > "$tmp/out" 2> "$tmp/err" < /dev/null && bad "-grid_spacing 0.1: exit status 0"
grep -qF "perilin: error: the scene file comes first" "$tmp/err" || bad "-grid_spacing 0.1: $(cat "$tmp/err")"
"$perilin" > "$tmp/out" 2> "$tmp/err" < /dev/null && bad "no argument: exit status 0"
grep -qF "perilin: error: usage: perilin SCENE.yaml" "$tmp/err" || bad "no argument: $(cat "$tmp/err")"
[ "$fail" -eq "$f" ] && echo "ok   an option before the scene file: the scene comes first, exit status 1"

# 5. summary.json: the versions and the command line
f=$fail
if ! "$perilin" "$scene" -output_dir "$tmp/run" -quiet > "$tmp/out" 2>&1 < /dev/null; then
  bad "tiny run: exit status $?"; sed 's/^/    /' "$tmp/out"
else
  python3 - "$tmp/run/summary.json" "$tmp/version" "$perilin" "$scene" "$tmp/run" << 'EOF' || fail=1
import json, sys
s = json.load(open(sys.argv[1]))
v = dict(l.split(" ", 1) for l in open(sys.argv[2]).read().splitlines())
want = {"perilin": v["perilin"], "petsc": v["PETSc"], "slepc": v["SLEPc"]}
ok = True
if s.get("build") != want:
    print("FAIL summary.json: build %r, -version says %r" % (s.get("build"), want)); ok = False
cl = [sys.argv[3], sys.argv[4], "-output_dir", sys.argv[5], "-quiet"]
if s.get("command_line") != cl:
    print("FAIL summary.json: command_line %r, expected %r" % (s.get("command_line"), cl)); ok = False
sys.exit(0 if ok else 1)
EOF
fi
[ "$fail" -eq "$f" ] && echo "ok   summary.json: build versions and command line"
[ "$fail" -eq 0 ]
