#!/usr/bin/env bash
# Effect of --density on size, time and quality.
# Usage: density_sweep.sh K MODEL.off...   (env DENSITIES="0 0.25 ...", QUALITY=1.414, RANKS=2,
# EXTRA="--no-heal")
set -euo pipefail
source "$(dirname "$0")/../common.sh"
k=$1; shift
densities=(${DENSITIES:-0 0.25 0.5 1 2})
ranks=${RANKS:-1}
extra=(${EXTRA:-})
[ -n "${QUALITY:-}" ] && extra+=(--quality "$QUALITY")
launch=()
[ "$ranks" -gt 1 ] && launch=(mpirun -np "$ranks")
make_work_dir
printf "%-22s %7s %9s %8s %8s %10s %10s %9s %8s %9s\n" model density tets wall_s heal_s amips_avg amips_max min_dih \
  "<5deg" retries
for model in "$@"; do
  for d in "${densities[@]}"; do
    "${launch[@]}" "$partet" mesh "$model" -o "$work/out" --pieces "$k" --density "$d" --report "$work/r.json" \
      --quiet "${extra[@]}"
    q=$("$partet" check --json "$model" "$work/out" | python3 -c 'import json, sys; q = json.load(sys.stdin)["quality"]
print(q["amips_avg"], q["amips_max"], q["min_dihedral_deg"], q["tets_below_5deg"])')
    r=$(python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))
print(r["counts"]["output_tets"], "%.2f" % r["total_seconds"], "%.2f" % r["stage_seconds"].get("seam_healing", 0))' \
      "$work/r.json")
    retries=$(python3 -c 'import json, sys; print(len(json.load(open(sys.argv[1]))["retries"]))' "$work/r.json")
    read -r tets wall heal <<< "$r"
    printf "%-22s %7s %9s %8s %8s %10.4g %10.4g %9.4g %8s %9s\n" "$(basename "$model")" "$d" "$tets" "$wall" "$heal" \
      $q "$retries"
  done
done
