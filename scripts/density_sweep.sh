#!/usr/bin/env bash
# Effect of --density on size, time and quality. Usage: density_sweep.sh K MODEL.off... (env DENSITIES)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
partet=${PARTET:-$here/../build/partet}
k=$1; shift
densities=(${DENSITIES:-0 0.25 0.5 1 2})
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [ "$(id -u)" -eq 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
printf "%-22s %7s %9s %8s %10s %10s %9s %8s\n" model density tets wall_s amips_avg amips_max min_dih "<5deg"
for model in "$@"; do
  for d in "${densities[@]}"; do
    /usr/bin/time -f "%e" -o "$work/t" "$partet" mesh "$model" -o "$work/out" --pieces "$k" --density "$d" --quiet
    "$partet" check "$model" "$work/out" > "$work/c"
    q=$(sed -n 's/^quality: AMIPS avg \([^ ]*\) max \([^;]*\); dihedral min \([^ ]*\) max [^;]*; tets <5deg \([0-9]*\).*/\1 \2 \3 \4/p' "$work/c")
    printf "%-22s %7s %9s %8s %10s %10s %9s %8s\n" "$(basename "$model")" "$d" "$(head -1 "$work/out.ele" | awk '{print $1}')" "$(cat "$work/t")" $q
  done
done
