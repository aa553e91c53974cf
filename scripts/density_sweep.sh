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
    q=$("$partet" check --json "$model" "$work/out" | python3 -c 'import json, sys; q = json.load(sys.stdin)["quality"]
print(q["amips_avg"], q["amips_max"], q["min_dihedral_deg"], q["tets_below_5deg"])')
    printf "%-22s %7s %9s %8s %10s %10s %9s %8s\n" "$(basename "$model")" "$d" "$(head -1 "$work/out.ele" | awk '{print $1}')" "$(cat "$work/t")" $q
  done
done
