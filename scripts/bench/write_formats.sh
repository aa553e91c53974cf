#!/usr/bin/env bash
# How long writing each output format takes, and how large its files are, by number of ranks:
# the median over RUNS runs of the report's stage_seconds.write (rank 0 writes every format alone
# except xdmf, whose HDF5 files every rank writes at once), with the mesh itself the same in every
# run. Prints a markdown table.
# Usage: write_formats.sh [-r RUNS] [-k PIECES] [-n "RANKS..."] [-f "FORMATS..."] [-l LOOPS] INPUT.off
#   -l LOOPS  Loop-subdivide the input first (partet refine-surface --loop LOOPS)
source "$(dirname "$0")/../common.sh"
runs=3 pieces=4 ranks="1 2" formats="tetgen vtu msh xdmf" loops=0
while getopts "r:k:n:f:l:" opt; do
  case $opt in
    r) runs=$OPTARG ;; k) pieces=$OPTARG ;; n) ranks=$OPTARG ;; f) formats=$OPTARG ;; l) loops=$OPTARG ;;
    *) exit 2 ;;
  esac
done
shift $((OPTIND - 1))
input=${1:?usage: write_formats.sh [options] INPUT.off}
make_work_dir
if [ "$loops" -gt 0 ]; then
  "$partet" refine-surface "$input" --loop "$loops" -o "$work/input.off" > /dev/null
  input=$work/input.off
fi
faces=$(sed -n 2p "$input" | awk '{print $2}')
echo "write_formats: $(basename "$input") ($faces faces), K=$pieces, $runs runs each, $(nproc) cores"
echo
echo "| format | ranks | write s (median) | total s (median) | files MB | tets |"
echo "|---|---|---|---|---|---|"
for format in $formats; do
  for n in $ranks; do
    writes=() totals=()
    for ((i = 0; i < runs; i++)); do
      rm -rf "$work/out" && mkdir "$work/out"
      mpiexec --oversubscribe -n "$n" "$partet" mesh "$input" -o "$work/out/m" -k "$pieces" --format "$format" \
        --report "$work/r.json" --quiet
      read -r write total tets < <(/usr/bin/python3 -c "
import json; r = json.load(open('$work/r.json'))
print(r['stage_seconds']['write'], r['total_seconds'], r['counts']['output_tets'])")
      writes+=("$write") totals+=("$total")
    done
    megabytes=$(du -cb "$work"/out/m* | tail -n 1 | awk '{printf "%.1f", $1 / 1e6}')
    printf "| %s | %s | %.2f | %.2f | %s | %s |\n" "$format" "$n" "$(printf "%s\n" "${writes[@]}" | median)" \
      "$(printf "%s\n" "${totals[@]}" | median)" "$megabytes" "$tets"
  done
done
