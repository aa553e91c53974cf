#!/usr/bin/env bash
# How long writing each output format takes, and how large its files are, by number of ranks:
# the median over RUNS runs of the report's stage_seconds.write, with the mesh itself the same in
# every run. Rank 0 writes the single-file formats (the other ranks format the TetGen files'
# lines); every rank writes its block of an XDMF set's HDF5 files, and its share of a .pvtu set's
# piece files ("files per rank": the median counts each rank wrote). With several binaries (-b)
# the runs alternate between them, so they are timed on the same machine state, and each row
# gives the md5 of the files (the binaries must write the same bytes). Prints a markdown table.
# Usage: write_formats.sh [-r RUNS] [-k PIECES] [-n "RANKS..."] [-f "FORMATS..."] [-l LOOPS] [-b "BINARIES..."] INPUT.off
#   -l LOOPS  Loop-subdivide the input first (partet refine-surface --loop LOOPS)
source "$(dirname "$0")/../common.sh"
runs=3 pieces=4 ranks="1 2" formats="tetgen vtu msh xdmf" loops=0 binaries=$partet
while getopts "r:k:n:f:l:b:" opt; do
  case $opt in
    r) runs=$OPTARG ;; k) pieces=$OPTARG ;; n) ranks=$OPTARG ;; f) formats=$OPTARG ;; l) loops=$OPTARG ;;
    b) binaries=$OPTARG ;;
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
echo "| format | ranks | binary | write s (median) | total s (median) | files per rank | files MB | tets | md5 |"
echo "|---|---|---|---|---|---|---|---|---|"
for format in $formats; do
  for n in $ranks; do
    declare -A writes=() totals=() written=() sizes=() tets=() sums=()
    for ((i = 0; i < runs; i++)); do
      for binary in $binaries; do
        rm -rf "$work/out" && mkdir "$work/out"
        mpiexec --oversubscribe -n "$n" "$binary" mesh "$input" -o "$work/out/m" -k "$pieces" --format "$format" \
          --report "$work/r.json" --quiet
        read -r write total count files < <(/usr/bin/python3 -c "
import json; r = json.load(open('$work/r.json'))
print(r['stage_seconds']['write'], r['total_seconds'], r['counts']['output_tets'],
      '/'.join(str(int(x.get('piece_files_written', 0))) for x in r['rank']))")
        writes[$binary]+="$write " totals[$binary]+="$total " written[$binary]=$files tets[$binary]=$count
        sizes[$binary]=$(du -cb "$work"/out/m* | tail -n 1 | awk '{printf "%.1f", $1 / 1e6}')
        sums[$binary]=$(cd "$work/out" && md5sum m* | md5sum | cut -c1-12)
      done
    done
    for binary in $binaries; do
      printf "| %s | %s | %s | %.2f | %.2f | %s | %s | %s | %s |\n" "$format" "$n" "$(basename "$binary")" \
        "$(tr ' ' '\n' <<< "${writes[$binary]}" | grep . | median)" \
        "$(tr ' ' '\n' <<< "${totals[$binary]}" | grep . | median)" "${written[$binary]}" "${sizes[$binary]}" \
        "${tets[$binary]}" "${sums[$binary]}"
    done
  done
done
