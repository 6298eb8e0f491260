#!/usr/bin/env bash
# Calls run one way (docs/design.md, "Layers"): each folder may include only the headers of its
# own layer and those below it, and no symbol of a higher folder may be referenced from a lower
# one. Two checks:
#   1. the #include lines of every source and header against the allow-list below;
#   2. the call graph of the built library (nm on the object files): the folders' dependencies
#      must form no cycle and must respect the order below.
#   3. within each folder, the calls between its files form no cycle (issue 25): every file can be
#      read knowing only the files it calls, and a folder's files have an order from the top down.
# Usage: layering.sh REPO OBJDIR   (OBJDIR: the perilin_core object directory of a build)
set -euo pipefail
repo=$1 objdir=$2
fail=0

# Folders from the top down. A folder may use the folders after it, never those before it.
order=(src/main src src/analysis src/system src/disc src/model_api models src/scene src/output src/sys)
# Headers a folder may include (besides system and library headers).
declare -A allow=(
  [src/main]="perilin.h perilin/private/output.h perilin/private/sys.h"
  [src]="perilin.h perilin/private/problem.h perilin/private/analysis.h perilin/private/system.h perilin/private/scene_file.h perilin/private/model_registry.h perilin/private/sys.h"
  [src/analysis]="perilin/private/analysis.h perilin/private/system.h analysis_list.h"
  [src/system]="perilin/private/system.h perilin/private/contact.h perilin/private/crack_surfaces.h perilin/private/mass.h perilin/private/fields.h perilin/private/conditions.h perilin/private/stiffness.h perilin/private/bondstate.h perilin/private/disc.h perilin/private/model_registry.h perilin/private/output.h perilin/private/scene_file.h perilin/private/sys.h"
  [src/disc]="perilin/private/disc.h perilin/private/sys.h perilin/private/gmsh_api.h"
  [src/model_api]="perilin/private/model_registry.h perilin/private/sys.h ../../models/model_list.h"
  [models]="perilin/model.h"
  [src/scene]="perilin/private/scene_file.h perilin/private/sys.h"
  [src/output]="perilin/private/output.h perilin/private/sys.h"
  [src/sys]="perilin/private/sys.h"
  [include/perilin]="perilin/types.h perilin/scene.h"
  [include/perilin/private]="perilin/types.h perilin/scene.h perilin/model.h perilin.h perilin/private/sys.h perilin/private/scene_file.h perilin/private/output.h perilin/private/disc.h perilin/private/model_registry.h perilin/private/mass.h perilin/private/fields.h perilin/private/conditions.h perilin/private/stiffness.h perilin/private/bondstate.h perilin/private/crack_surfaces.h perilin/private/contact.h perilin/private/system.h perilin/private/analysis.h"
)
# Within include/perilin/private, a header may include only those listed before it here.
hdr_order=(sys scene_file output disc model_registry mass fields conditions stiffness bondstate crack_surfaces contact system analysis problem)

folder_of() { # a source path relative to the repo -> its folder key
  case $1 in
    src/main.c) echo src/main ;;
    version.c) echo src/sys ;; # generated in the build tree (src/sys/version.cmake), declared in sys.h
    src/*/*) dirname "$1" ;;
    src/*) echo src ;;
    models/*) echo models ;;
    include/perilin/private/*) echo include/perilin/private ;;
    include/perilin/*) echo include/perilin ;;
    *) echo "" ;;
  esac
}

cd "$repo"
while IFS= read -r f; do
  key=$(folder_of "$f")
  [[ -n $key && -n ${allow[$key]+x} ]] || { echo "layering: $f is in no known folder; add it to tests/layering.sh"; fail=1; continue; }
  while IFS= read -r inc; do
    ok=0
    for a in ${allow[$key]}; do [[ $inc == "$a" ]] && ok=1; done
    if [[ $ok == 0 ]]; then echo "layering: $f includes \"$inc\", not allowed in $key (allowed: ${allow[$key]})"; fail=1; fi
  done < <(sed -n 's/^#include [<"]\(perilin[^>"]*\|analysis_list.h\|..\/..\/models\/model_list.h\)[>"].*/\1/p' "$f")
done < <(find src models include/perilin -name '*.[ch]' ! -name '*_list.h' | sort)

# private headers: only those before it in hdr_order
for ((i = 0; i < ${#hdr_order[@]}; i++)); do
  h=include/perilin/private/${hdr_order[i]}.h
  while IFS= read -r inc; do
    base=$(basename "$inc" .h)
    for ((j = i; j < ${#hdr_order[@]}; j++)); do
      if [[ $inc == perilin/private/${hdr_order[j]}.h ]]; then echo "layering: $h includes $inc, a header at or above its own layer"; fail=1; fi
    done
  done < <(sed -n 's/^#include [<"]\(perilin\/private\/[^>"]*\)[>"].*/\1/p' "$h")
done

# 2. the call graph between folders, from the object files
declare -A def_folder
objs=$(find "$objdir" -name '*.o' | sort)
[[ -n $objs ]] || { echo "layering: no object files under $objdir"; exit 1; }
obj_folder() { # .../perilin_core.dir/src/system/solve.c.o -> src/system
  local rel=${1#"$objdir"/}
  rel=${rel%.o}
  folder_of "$rel"
}
declare -A def_file
for o in $objs; do
  fo=$(obj_folder "$o")
  for s in $(nm --defined-only -g "$o" | awk '$2 ~ /[TDBR]/ {print $3}'); do
    def_folder[$s]=$fo
    def_file[$s]=${o#"$objdir"/}
  done
done
rank() { for ((k = 0; k < ${#order[@]}; k++)); do [[ ${order[k]} == "$1" ]] && { echo $k; return; }; done; echo -1; }
for o in $objs; do
  fo=$(obj_folder "$o")
  ro=$(rank "$fo")
  for s in $(nm -u "$o" | awk '{print $2}'); do
    fd=${def_folder[$s]:-}
    [[ -z $fd || $fd == "$fo" ]] && continue
    rd=$(rank "$fd")
    if ((rd < ro)); then echo "layering: ${o#"$objdir"/} ($fo) calls $s, defined in $fd, a higher layer"; fail=1; fi
  done
done

# 3. file-level cycles within a folder: tsort names the files of any loop
edges=$(for o in $objs; do
  fo=$(obj_folder "$o")
  for s in $(nm -u "$o" | awk '{print $2}'); do
    fd=${def_file[$s]:-}
    [[ -n $fd && ${def_folder[$s]} == "$fo" && $fd != "${o#"$objdir"/}" ]] && echo "${o#"$objdir"/} $fd"
  done
done | sed 's/\.o / /; s/\.o$//' | sort -u)
loops=$(printf '%s\n' "$edges" | tsort 2>&1 > /dev/null | grep -v 'input contains a loop' | sed 's/^tsort: //' || true)
if [[ -n $loops ]]; then
  echo "layering: files of one folder call each other in a cycle (move the shared function down, or split the file):"
  printf '%s\n' "$loops" | sort -u | sed 's/^/  /'
  printf '%s\n' "$edges" | while read -r a b; do printf '%s\n' "$loops" | grep -qx "$a" && printf '%s\n' "$loops" | grep -qx "$b" && echo "    $a -> $b"; done
  fail=1
fi
if [[ $fail == 0 ]]; then echo "ok: includes follow the layers; no call from a lower folder to a higher one (${#order[@]} folders); no call cycle between the files of a folder"; fi
exit $fail
