#!/usr/bin/env bash
# Peak memory per rank from partet's --report, next to `tetgen -pYQ` on the same input.
# Usage: memory_table.sh INPUT.off   (env: ONE_RANK_KS="1 2 4 8 16", TWO_RANK_KS="2 4 8")
set -euo pipefail
source "$(dirname "$0")/common.sh"
input=$(realpath "$1")
make_work_dir
cp "$input" "$work/input.off"
(cd "$work" && /usr/bin/time -f "%e %M" -o "$work/t" tetgen -pYQ input.off > /dev/null)
read -r tg_wall tg_kb < "$work/t"
tg_mb=$(awk -v k="$tg_kb" 'BEGIN {printf "%.0f", k / 1024}')
echo "tetgen -pYQ: ${tg_wall} s, peak RSS ${tg_mb} MB"
printf "%-14s %5s %8s   %s\n" run pieces wall_s "per rank: process MB / its TetGen processes MB  (largest / tetgen)"
run() {
  local n=$1 k=$2
  local launch=()
  [ "$n" -gt 1 ] && launch=(mpirun -np "$n" --oversubscribe --bind-to none)
  "${launch[@]}" "$partet" mesh "$work/input.off" -o "$work/out" --pieces "$k" --quiet --report "$work/r.json"
  python3 - "$work/r.json" "$tg_mb" "$n" "$k" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); tg = float(sys.argv[2])
ranks = "  ".join(f"r{x['rank']}: {x['peak_rss_mb']:.0f} / {x['tetgen_process_peak_rss_mb']:.0f}" for x in r["rank"])
largest = max(max(x["peak_rss_mb"], x["tetgen_process_peak_rss_mb"]) for x in r["rank"])
print(f"{'np=' + sys.argv[3] + ' k=' + sys.argv[4]:<14} {r['pieces']:>5} {r['total_seconds']:8.2f}   {ranks}   ({largest / tg:.2f})")
PY
}
for k in ${ONE_RANK_KS:-1 2 4 8 16}; do run 1 "$k"; done
for k in ${TWO_RANK_KS:-2 4 8}; do run 2 "$k"; done
