#!/usr/bin/env bash
# What --checkpoint costs and what it saves, on one input: per run, alternating, a run without it
# (plain), a run keeping every piece in an empty DIR (keep), and a rerun with that DIR full
# (resume: every piece taken); then the medians, the ratios to plain, the DIR's size, and the
# files' md5 (all three must write the same bytes). TetGen alone is run once at the start
# (-t), as the yardstick for resume. Figures, not a test: time it on a quiet machine.
#
# Usage: checkpoint_cost.sh [-r RUNS] [-n RANKS] [-k K] [-t] INPUT
#   -r  repetitions (default 3)   -n  MPI ranks (default 2)   -k  pieces (default 16)
#   -t  also time `tetgen -pYQ` on INPUT once
set -euo pipefail
source "$(dirname "$0")/../common.sh"
runs=3 ranks=2 k=16 tetgen=""
while getopts "r:n:k:t" opt; do
  case $opt in
    r) runs=$OPTARG ;; n) ranks=$OPTARG ;; k) k=$OPTARG ;; t) tetgen=1 ;;
    *) sed -n '2,10p' "$0"; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[ $# -eq 1 ] || { sed -n '2,10p' "$0"; exit 2; }
input=$1
make_work_dir
if [ -n "$tetgen" ]; then
  cp "$input" "$work/alone.off"
  timed "$work/t-tetgen" tetgen -pYQ "$work/alone.off" > /dev/null
  echo "tetgen -pYQ: $(cut -d' ' -f1 "$work/t-tetgen") s"
fi
mesh() {  # NAME RUN [options]: one timed run into $work/NAME
  local name=$1 run=$2
  shift 2
  mkdir -p "$work/$name"
  timed "$work/t-$name-$run" mpirun -np "$ranks" "$partet" mesh "$input" -k "$k" -o "$work/$name/m" --quiet "$@"
  (cd "$work/$name" && md5sum m.node m.ele m.face m.neigh | md5sum | cut -c1-12) > "$work/md5-$name-$run"
}
for ((run = 1; run <= runs; run++)); do
  rm -rf "$work/ck"
  mesh plain "$run"
  mesh keep "$run" --checkpoint "$work/ck"
  mesh resume "$run" --checkpoint "$work/ck"
done
plain=$(cat "$work"/t-plain-* | cut -d' ' -f1 | median)
printf "%-8s %8s %8s   %s\n" run "median s" "/ plain" "runs (s), md5"
for name in plain keep resume; do
  m=$(cat "$work"/t-$name-* | cut -d' ' -f1 | median)
  printf "%-8s %8.2f %8.3f   %s  %s\n" "$name" "$m" "$(echo "$m / $plain" | bc -l)" \
    "$(cat "$work"/t-$name-* | cut -d' ' -f1 | tr '\n' ' ')" "$(sort -u "$work"/md5-$name-* | tr '\n' ' ')"
done
echo "checkpoint directory: $(du -sm "$work/ck" | cut -f1) MB in $(ls "$work/ck" | wc -l) files"
