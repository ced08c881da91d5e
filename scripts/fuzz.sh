#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Runs the libFuzzer targets of build-fuzz/ (built by `scripts/setup.sh --fuzz`, which
# ./test.sh runs) for SECONDS in all, split evenly: the case reader, the particle-table reader
# and the mesh reader (fuzz/). Each is seeded with the repository's own files (every case file
# under cases/ and tests/, fuzz/seeds/ (cases small enough for the fuzz budget, particle tables), .msh files gmsh writes from
# meshes/coupled_bar_h4.geo) and keeps what it learns in build-fuzz/corpus/<target>/. Prints,
# per target, the executions, the coverage (edges) and the crashes; a crashing input is kept
# in build-fuzz/crashes/<target>/ and the exit is 1. Exit 77 (a skip for ctest) when the fuzz
# build is missing.
# usage: scripts/fuzz.sh [SECONDS]   (default 600)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
seconds=${1:-600}
fuzz_dir="$root/build-fuzz/fuzz"
targets=(fuzz_case fuzz_particle_table fuzz_mesh)
for t in "${targets[@]}"; do
  if [[ ! -x "$fuzz_dir/$t" ]]; then
    echo "fuzz: $fuzz_dir/$t is not built; run scripts/setup.sh --fuzz (./test.sh does)" >&2
    exit 77
  fi
done

seed_dir="$root/build-fuzz/seeds"
rm -rf "$seed_dir"
mkdir -p "$seed_dir"/{fuzz_case,fuzz_particle_table,fuzz_mesh}
find "$root/cases" "$root/tests" "$root/fuzz/seeds/case" -name '*.yaml' -not -path '*/results/*' \
  -exec cp -t "$seed_dir/fuzz_case" --backup=numbered {} +
cp "$root"/fuzz/seeds/particle_table/*.csv "$seed_dir/fuzz_particle_table/"
for format in msh22 msh41; do
  gmsh -3 -format "$format" "$root/meshes/coupled_bar_h4.geo" -o "$seed_dir/fuzz_mesh/bar_$format.msh" >/dev/null
done
gmsh -3 -format msh41 -bin "$root/meshes/coupled_bar_h4.geo" -o "$seed_dir/fuzz_mesh/bar_msh41_binary.msh" >/dev/null

# Leaks are not reported: PETSc and Open MPI keep their allocations to the end of the process.
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1
per_target=$((seconds / ${#targets[@]}))
status=0
for t in "${targets[@]}"; do
  corpus="$root/build-fuzz/corpus/$t"
  crashes="$root/build-fuzz/crashes/$t"
  rm -rf "$crashes"
  mkdir -p "$corpus" "$crashes"
  log="$root/build-fuzz/$t.log"
  # The targets' scratch files (fuzz/fuzz_input.hpp) and MPI's go to a folder of the run's own,
  # removed after it: a folder per process under /tmp would pile up from run to run.
  scratch="$root/build-fuzz/tmp/$t"
  rm -rf "$scratch"
  mkdir -p "$scratch"
  # -timeout: an input that takes longer is a defect too (a reader that hangs); -rss_limit_mb:
  # the readers refuse what needs more than the fuzz budget (fuzz/fuzz_input.hpp) long before.
  set +e
  (cd "$root/build-fuzz" && TMPDIR="$scratch" "$fuzz_dir/$t" "$corpus" "$seed_dir/$t" -max_total_time="$per_target" -timeout=30 \
      -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$crashes/" >"$log" 2>&1)
  code=$?
  set -e
  rm -rf "$scratch"
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo 0)
  # crash-, timeout- and oom- files are failures; slow-unit- files (over 10 s, under the
  # timeout) are not.
  found=$(find "$crashes" -type f \( -name 'crash-*' -o -name 'timeout-*' -o -name 'oom-*' -o -name 'leak-*' \) | wc -l)
  echo "fuzz: $t: ${per_target} s, ${runs} executions, coverage ${cov} edges, ${found} crashing inputs (log: $log)"
  if ((code != 0 || found > 0)); then
    grep -E 'ERROR|fuzz:|SUMMARY|runtime error|Test unit written' "$log" | head -n 12 >&2 || true
    status=1
  fi
done
exit $status
