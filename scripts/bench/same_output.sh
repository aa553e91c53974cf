#!/usr/bin/env bash
# Whether two partet binaries write the same bytes: every model in a directory (default: the
# shared models) at each K, with and without --quality, compared file by file (TetGen files).
# With -s, the same mesh in another tet order: the same .node and .face rows and the same tets
# (the .ele rows without their numbers, as a multiset); .neigh and the comments (the set ID
# names the order) are not compared.
# With -n N, the new binary runs under `mpirun -np N` (pieces meshed, and split, on other ranks).
# Prints one line per difference and a count; exit 0 when every output is identical.
# Usage: same_output.sh OLD_PARTET NEW_PARTET [-d DIR] [-k "2 4 8"] [-q "none 1.414"] [-s] [-n N]
set -uo pipefail
source "$(dirname "$0")/../common.sh"
old=$(realpath "$1") new=$(realpath "$2")
shift 2
dir=$here/../../shared/meshes ks="2 4 8" qualities="none 1.414" as_sets=0 launch=()
while getopts "d:k:q:sn:" opt; do
  case $opt in
    d) dir=$OPTARG ;; k) ks=$OPTARG ;; q) qualities=$OPTARG ;; s) as_sets=1 ;; n) launch=(mpirun -np "$OPTARG") ;;
    *) sed -n '2,8p' "$0"; exit 2 ;;
  esac
done
# The .ele rows without their numbers (and comments), sorted.
tet_rows() { grep -v '^#' "$1" | tail -n +2 | awk '{$1 = ""; print}' | sort; }
same() {
  if [ "$as_sets" = 1 ] && [ "$1" = ele ]; then
    cmp -s <(tet_rows "$work/old.ele") <(tet_rows "$work/new.ele")
  elif [ "$as_sets" = 1 ]; then
    cmp -s <(grep -v '^#' "$work/old.$1") <(grep -v '^#' "$work/new.$1")
  else
    cmp -s "$work/old.$1" "$work/new.$1"
  fi
}
make_work_dir
runs=0 different=0 failed=0
for model in "$dir"/*.off; do
  name=$(basename "$model" .off)
  for k in $ks; do
    for q in $qualities; do
      args=(--pieces "$k" --quiet)
      [ "$q" = none ] || args+=(--quality "$q")
      runs=$((runs + 1))
      if ! "$old" mesh "$model" -o "$work/old" "${args[@]}" > /dev/null 2>&1 ||
         ! "${launch[@]}" "$new" mesh "$model" -o "$work/new" "${args[@]}" > /dev/null 2>&1; then
        echo "FAILED: $name k=$k q=$q"; failed=$((failed + 1)); continue
      fi
      exts="node ele face neigh"
      [ "$as_sets" = 1 ] && exts="node ele face"
      for ext in $exts; do
        if ! same "$ext"; then
          echo "DIFFERENT: $name k=$k q=$q .$ext"; different=$((different + 1)); break
        fi
      done
    done
  done
done
echo "$runs runs: $((runs - different - failed)) identical, $different different, $failed failed"
[ "$different" -eq 0 ] && [ "$failed" -eq 0 ]
