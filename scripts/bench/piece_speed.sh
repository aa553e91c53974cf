#!/usr/bin/env bash
# Does a piece mesh at TetGen's own speed inside partet? Runs `mpirun -np RANKS partet mesh
# --pieces K --dump-pieces`, then `tetgen -pYQ` on every dumped piece, RANKS at a time (as the
# ranks ran them), and prints per piece the report's meshing time inside partet (the child's
# wall time: TetGen plus the piece's checks and the reply) against TetGen's, medians of RUNS.
# Time it on a quiet machine.
#
# Usage: piece_speed.sh [-r RUNS] [-n RANKS] [-k K] INPUT
set -euo pipefail
source "$(dirname "$0")/../common.sh"
runs=3 ranks=2 k=2
while getopts "r:n:k:" opt; do
  case $opt in
    r) runs=$OPTARG ;; n) ranks=$OPTARG ;; k) k=$OPTARG ;; *) sed -n '2,8p' "$0"; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[ $# -eq 1 ] || { sed -n '2,8p' "$0"; exit 2; }
make_work_dir
launch=()
[ "$ranks" -gt 1 ] && launch=(mpirun -np "$ranks")
mkdir -p "$work/pieces"
for r in $(seq "$runs"); do
  "${launch[@]}" "$partet" mesh "$1" -o "$work/out" --pieces "$k" --dump-pieces "$work/pieces" \
    --report "$work/r$r.json" --quiet
  # TetGen on the pieces, RANKS side by side, largest first (as partet hands them out).
  pieces=$(ls -S "$work"/pieces/piece_*.off)
  echo "$pieces" | xargs -P "$ranks" -I{} bash -c \
    'cd "$(dirname {})" && timed "{}.t'"$r"'" tetgen -pYQ "$(basename {})" > /dev/null'
done
/usr/bin/python3 - "$work" "$runs" <<'PY'
import json, statistics, sys, glob, os
work, runs = sys.argv[1], int(sys.argv[2])
inside = {}
for r in range(1, runs + 1):
    for p in json.load(open(f"{work}/r{r}.json"))["piece"]:
        inside.setdefault(p["index"], []).append(p["tetgen_seconds"])
print("%6s %10s %10s %12s %8s" % ("piece", "triangles", "tetgen_s", "in_partet_s", "ratio"))
ratios = []
for index in sorted(inside):
    off = f"{work}/pieces/piece_{index}.off"
    alone = [float(open(f"{off}.t{r}").read().split()[0]) for r in range(1, runs + 1)]
    triangles = int(open(off).readlines()[1].split()[1])
    a, b = statistics.median(alone), statistics.median(inside[index])
    ratios.append(b / a)
    print("%6d %10d %10.2f %12.2f %8.3f" % (index, triangles, a, b, b / a))
print("median ratio %.3f, max %.3f" % (statistics.median(ratios), max(ratios)))
PY
