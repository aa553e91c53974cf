#!/usr/bin/env bash
# What seam healing costs in wall time: for each K, runs `partet mesh` with the default healing
# and with --no-heal (which still removes the cut vertices, as every run must), alternating, and
# prints per mode the medians of the run's wall time, of the seam_healing stage and of its share
# of the run, then the difference of the medians (healing's added cost) as a share of the run.
# No --check: the run as a user runs it. Figures, not a test: time it on a quiet machine.
#
# Usage: heal_cost.sh [-r RUNS] [-n RANKS] [-k "K ..."] [-q QUALITY] [-x "ARGS"] INPUT
#   -r  repetitions (default 5)   -n  MPI ranks (default 2)   -k  piece counts (default "2 4 8")
#   -q  radius-edge bound (default none)   -x  more partet mesh arguments for both modes
set -euo pipefail
source "$(dirname "$0")/../common.sh"
runs=5 ranks=2 ks="2 4 8" quality="" extra=""
while getopts "r:n:k:q:x:" opt; do
  case $opt in
    r) runs=$OPTARG ;; n) ranks=$OPTARG ;; k) ks=$OPTARG ;; q) quality=$OPTARG ;; x) extra=$OPTARG ;;
    *) sed -n '2,11p' "$0"; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[ $# -eq 1 ] || { sed -n '2,11p' "$0"; exit 2; }
input=$1
make_work_dir
launch=()
[ "$ranks" -gt 1 ] && launch=(mpirun -np "$ranks")
switches=()
[ -n "$quality" ] && switches+=(--quality "$quality")
# shellcheck disable=SC2206
[ -n "$extra" ] && switches+=($extra)
heal_mode=default
[ -z "$quality" ] && heal_mode="default (no healing without --quality)"

# "total_s seam_healing_s" of a report.
figures() {
  /usr/bin/python3 -c 'import json, sys
r = json.load(open(sys.argv[1]))
print(r["total_seconds"], r["stage_seconds"].get("seam_healing", 0))' "$1"
}

printf "%-6s %-10s %8s %8s %8s\n" K mode wall_s heal_s heal_share
declare -A wall
for k in $ks; do
  : > "$work/default" && : > "$work/no-heal"
  for ((r = 0; r < runs; ++r)); do
    for mode in default no-heal; do
      flags=("${switches[@]}")
      [ "$mode" = no-heal ] && flags+=(--no-heal)
      "${launch[@]}" "$partet" mesh "$input" -o "$work/out" --pieces "$k" "${flags[@]}" --report "$work/r.json" --quiet
      figures "$work/r.json" >> "$work/$mode"
    done
  done
  for mode in default no-heal; do
    wall[$mode]=$(awk '{print $1}' "$work/$mode" | median)
    heal=$(awk '{print $2}' "$work/$mode" | median)
    share=$(awk '{print 100 * $2 / $1}' "$work/$mode" | median)
    printf "%-6s %-10s %8.2f %8.3f %7.1f%%\n" "$k" "$mode" "${wall[$mode]}" "$heal" "$share"
  done
  awk -v a="${wall[default]}" -v b="${wall[no-heal]}" -v k="$k" \
    'BEGIN {printf "%-6s %-10s %8.2f %8s %7.1f%%   (healing'"'"'s added cost: default - no-heal, of the default run)\n", k, "added", a - b, "", 100 * (a - b) / a}'
done
echo "($runs runs per mode, $ranks ranks, $(basename "$input"), heal mode: $heal_mode)"
