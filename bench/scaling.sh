#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The thread-scaling table of docs/performance.md on this machine: the bonded block at 20k and
# 200k DEs (bond-steps/s) and the REV 10k tension to failure with BBF (steps/s of its time
# loop), on each thread count of THREADS, with the step's profile against one thread, and the
# one-core rate of the block (median of 5). Every run prints a fingerprint of its result: the
# same on every thread count when the results are the same to the bit.
#   bench/scaling.sh [BENCH]     BENCH: the bench_bonded_block command (default build/bench/...)
# Environment: THREADS (default 1,2,4,8,16 capped at the cores), REPEAT (default 3), and
# OMP_PROC_BIND / OMP_PLACES as the run should have them (default close / cores).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bench=${1:-$root/build/bench/bench_bonded_block}
cores=$(nproc)
default_threads=1
for t in 2 4 8 16 32 64; do
  if ((t <= cores)); then default_threads+=",$t"; fi
done
threads=${THREADS:-$default_threads}
repeat=${REPEAT:-3}
export OMP_PROC_BIND=${OMP_PROC_BIND:-close} OMP_PLACES=${OMP_PLACES:-cores}
block=$root/cases/bonded_block_tension/case.yaml

echo "== machine: $cores cores; $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2-)"
echo "== bonded block 20k DEs, 2000 steps, threads $threads, $repeat alternated runs"
$bench --steps 2000 --threads "$threads" --repeat "$repeat" --profile "$block"
echo "== bonded block 200k DEs (40 x 50 x 100), 200 steps, threads $threads, $repeat alternated runs"
$bench --steps 200 --threads "$threads" --repeat "$repeat" --set "dem.sample.counts=[40,50,100]" "$block"
echo "== REV 10k, tension to failure with BBF (cases/rev_failure L_bbf), threads $threads"
$bench --virtual-test "$root/cases/rev_failure/failure_tests.yaml" --sample rev_10k --test L_bbf \
  --threads "$threads" --profile
echo "== bonded block 20k DEs on one core, 2000 steps, median of 5"
$bench --steps 2000 --threads 1 --repeat 5 "$block"
