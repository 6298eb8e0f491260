#!/usr/bin/env bash
# valgrind.sh PERILIN EXAMPLES_DIR: valgrind memcheck (leaks, invalid reads and writes, use of
# uninitialized values) of one tiny case of each analysis: static, modal, quasi-static, dynamic
# (explicit and implicit). Exits 77
# (ctest SKIP_RETURN_CODE) when valgrind is absent. Each run takes 10-25 s under valgrind.
#
# Open MPI's noise: its own suppression file (uninitialized bytes in its buffers), and leaks
# whose stack passes through ompi_mpi_init or ompi_mpi_finalize (MCA components, hwloc, PMIx and
# ORTE keep or drop these allocations at exit). Leaks reached from our code are not suppressed:
# PETSc objects and MPI communicators perilin forgets still show.
set -u
perilin=$1
ex=$2
command -v valgrind > /dev/null || {
  echo "valgrind not found: skipped"
  exit 77
}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/openmpi-leaks.supp" << 'EOF'
{
   openmpi_init
   Memcheck:Leak
   match-leak-kinds: all
   ...
   fun:ompi_mpi_init
}
{
   openmpi_finalize
   Memcheck:Leak
   match-leak-kinds: all
   ...
   fun:ompi_mpi_finalize
}
EOF
supp=(--suppressions="$tmp/openmpi-leaks.supp")
for f in /usr/share/openmpi/openmpi-valgrind.supp /usr/share/openmpi/doc/openmpi-valgrind.supp; do
  [ -f "$f" ] && supp+=(--suppressions="$f")
done
# hwloc's x86 CPUID backend does not work under valgrind and says so on every run
export HWLOC_COMPONENTS=-x86
fail=0

# check NAME STDOUT_REGEX SCENE [OPTIONS...]
check() {
  local name=$1 expect=$2 scene=$3 code problem="" t0 t1
  shift 3
  t0=$(date +%s.%N)
  # deep stacks, so that the suppressions see ompi_mpi_init below the MCA components
  valgrind -q --error-exitcode=1 --leak-check=full --num-callers=64 "${supp[@]}" --log-file="$tmp/$name.vg" \
    "$perilin" "$ex/$scene" "$@" -output_dir "$tmp/$name-out" > "$tmp/$name.log" 2>&1 < /dev/null
  code=$?
  t1=$(date +%s.%N)
  if [ -s "$tmp/$name.vg" ]; then
    problem="valgrind reports errors"
  elif [ "$code" -ne 0 ]; then
    problem="exit code $code"
  elif ! grep -Eq -- "$expect" "$tmp/$name.log"; then
    problem="the output does not match '$expect'"
  fi
  if [ -n "$problem" ]; then
    echo "FAIL $name: $problem"
    head -c 20000 "$tmp/$name.vg" | sed 's/^/    /'
    tail -5 "$tmp/$name.log" | sed 's/^/    /'
    fail=$((fail + 1))
  else
    printf 'ok   %s (%.0f s)\n' "$name" "$(echo "$t1 - $t0" | bc)"
  fi
}

check static 'strain energy' pmb/plate_traction.yaml -grid_spacing 0.02
check modal 'modes \(Hz\)' lamina/modal.yaml -grid_spacing 0.05
check static_lps_lattice 'strain energy' pmb/plate_traction.yaml -grid_spacing 0.02 -model_type lps -material_nu 0.3 -model_calibration lattice -corrections_surface none
check quasistatic 'strain energy' antiplane/cracked_bar.yaml -grid_spacing 0.05 -analysis_min_step 0.25 -quiet
check dynamic_explicit 'explicit dynamics' ../tests/scenes/dynamic_crack.yaml -grid_spacing 0.05 -analysis_t_end 0.004
check dynamic_implicit 'implicit dynamics' ../tests/scenes/dynamic_crack.yaml -grid_spacing 0.05 -analysis_t_end 0.002 -analysis_integrator implicit -analysis_dt 4e-4

[ "$fail" -eq 0 ] && echo "valgrind: clean" || echo "valgrind: $fail run(s) failed"
[ "$fail" -eq 0 ]
