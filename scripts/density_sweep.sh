#!/usr/bin/env bash
# Effect of --density on size, time and quality. Usage: density_sweep.sh K MODEL.off... (env DENSITIES)
set -euo pipefail
source "$(dirname "$0")/common.sh"
k=$1; shift
densities=(${DENSITIES:-0 0.25 0.5 1 2})
make_work_dir
printf "%-22s %7s %9s %8s %10s %10s %9s %8s\n" model density tets wall_s amips_avg amips_max min_dih "<5deg"
for model in "$@"; do
  for d in "${densities[@]}"; do
    /usr/bin/time -f "%e" -o "$work/t" "$partet" mesh "$model" -o "$work/out" --pieces "$k" --density "$d" --quiet
    "$partet" check "$model" "$work/out" > "$work/c"
    q=$(sed -n 's/^quality: AMIPS avg \([^ ]*\) max \([^;]*\); dihedral min \([^ ]*\) max [^;]*; tets <5deg \([0-9]*\).*/\1 \2 \3 \4/p' "$work/c")
    printf "%-22s %7s %9s %8s %10s %10s %9s %8s\n" "$(basename "$model")" "$d" "$(head -1 "$work/out.ele" | awk '{print $1}')" "$(cat "$work/t")" $q
  done
done
