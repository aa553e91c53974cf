#!/usr/bin/env bash
# `partet check` on one output in one process and under mpirun on N ranks (each rank reading and
# checking its part of any set partet writes), alternating, R times each:
# the median wall time, the largest rank's peak memory and every rank's (medians over the runs,
# GNU time per process), and the check's verdict line. Figures, not a test: run it on a quiet
# machine. With -n 1 only the process alone is run.
#
# Usage: check_ranks.sh [-r R] [-n "2 4"] [-b BINARY] INPUT OUTPUT
#   OUTPUT: TetGen prefix, PREFIX.msh, PREFIX_i.msh, PREFIX.vtu, PREFIX.pvtu, PREFIX.mesh or
#   PREFIX.xdmf, as `partet check` takes it
set -euo pipefail
source "$(dirname "$0")/../common.sh"
runs=3 ranks="2 4" binary=partet
while getopts "r:n:b:" opt; do
  case $opt in
    r) runs=$OPTARG ;; n) ranks=$OPTARG ;; b) binary=$OPTARG ;;
    *) sed -n '2,9p' "$0"; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[ $# -eq 2 ] || { sed -n '2,9p' "$0"; exit 2; }
input=$1 output=$2
make_work_dir

# run N REPEAT: N=1 is the process alone; writes $work/N.REPEAT.rank* (seconds and KB per rank)
# and the wall time of the whole check.
run() {
  local n=$1 at=$2 start end
  start=$(date +%s.%N)
  if [ "$n" = 1 ]; then
    timed "$work/$n.$at.rank0" "$binary" check "$input" "$output" > "$work/log" 2>&1 || true
  else
    mpirun -np "$n" bash -c 'timed "$0.rank$OMPI_COMM_WORLD_RANK" "$@"' "$work/$n.$at" \
      "$binary" check "$input" "$output" > "$work/log" 2>&1 || true
  fi
  end=$(date +%s.%N)
  awk -v a="$start" -v b="$end" 'BEGIN {print b - a}' > "$work/$n.$at.wall"
  grep -q "check passed" "$work/log" || { cat "$work/log"; echo "CHECK FAILED ($n ranks)"; exit 1; }
  grep -m 1 "vertices" "$work/log" > "$work/$n.verdict"
}

configurations="1"
for n in $ranks; do [ "$n" = 1 ] || configurations+=" $n"; done
for at in $(seq "$runs"); do
  for n in $configurations; do run "$n" "$at"; done
done

echo "partet check $input $output: medians of $runs (wall s; peak MB per process)"
echo "| ranks | wall s | largest rank MB | each rank MB |"
echo "|---:|---:|---:|---|"
for n in $configurations; do
  wall=$(cat "$work/$n".*.wall | median)
  each=""
  largest=0
  for rank in $(seq 0 $((n - 1))); do
    mb=$(for at in $(seq "$runs"); do awk '{print $2 / 1024}' "$work/$n.$at.rank$rank"; done | median)
    each+="$(printf '%.0f' "$mb") "
    largest=$(echo "$mb $largest" | awk '{print ($1 > $2) ? $1 : $2}')
  done
  printf '| %s | %.1f | %.0f | %s|\n' "$([ "$n" = 1 ] && echo "1 (alone)" || echo "$n")" "$wall" "$largest" "$each"
done
for n in $configurations; do echo "$n: $(cat "$work/$n.verdict")"; done
