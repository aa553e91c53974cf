#!/usr/bin/env bash
# The stages outside the meshing (rank 0's serial time), for one or more partet binaries run
# alternately on the same input: per binary the median of each stage's seconds over the runs,
# their sum, and the report's serial_seconds (wall time during which no rank was meshing), and
# the files' md5 (the binaries must write the same bytes). Figures, not a test: time it on a
# quiet machine.
#
# Usage: serial_stages.sh [-r RUNS] [-n RANKS | -d] [-k K] [-o DIR] INPUT BINARY [BINARY ...]
#   -r  repetitions (default 3)   -n  MPI ranks (default 2)   -k  pieces (default 16)
#   -d  one process without mpirun (as `partet mesh` on a laptop: not bound to one core)
#   -o  keep the reports there (rB-R.json: binary B, run R), e.g. for scripts/bench/amdahl.py
set -euo pipefail
source "$(dirname "$0")/../common.sh"
runs=3 ranks=2 k=16 keep="" direct=""
while getopts "r:n:k:o:d" opt; do
  case $opt in
    r) runs=$OPTARG ;; n) ranks=$OPTARG ;; k) k=$OPTARG ;; o) keep=$OPTARG ;; d) direct=1 ;;
    *) sed -n '2,11p' "$0"; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[ $# -ge 2 ] || { sed -n '2,11p' "$0"; exit 2; }
input=$1
shift
make_work_dir
stages="read validate partition closure merge seam_healing write"

for ((run = 1; run <= runs; run++)); do
  for ((b = 1; b <= $#; b++)); do
    binary=${!b}
    mkdir -p "$work/out$b"
    launch=(mpirun -np "$ranks")
    [ -z "$direct" ] || launch=()
    "${launch[@]}" "$binary" mesh "$input" -k "$k" -o "$work/out$b/m" --quiet --report "$work/r$b-$run.json"
    (cd "$work/out$b" && md5sum m.node m.ele m.face m.neigh | md5sum | cut -c1-12) > "$work/md5-$b-$run"
  done
done
if [ -n "$keep" ]; then mkdir -p "$keep" && cp "$work"/r*.json "$keep"/; fi

printf "%-28s" binary
for s in $stages; do printf " %9s" "$s"; done
printf " %9s %9s %9s  %s\n" sum no_mesh total md5
for ((b = 1; b <= $#; b++)); do
  printf "%-28s" "$(basename "${!b}")"
  for s in $stages sum serial_seconds total_seconds; do
    for ((run = 1; run <= runs; run++)); do
      /usr/bin/python3 -c 'import json, sys
r = json.load(open(sys.argv[1])); st = r["stage_seconds"]; s = sys.argv[2]
stages = "read validate partition closure merge seam_healing write".split()
print(sum(st.get(x, 0) for x in stages) if s == "sum" else r[s] if s in r else st.get(s, 0))' \
        "$work/r$b-$run.json" "$s"
    done | median | xargs printf " %9.2f"
  done
  printf "  %s\n" "$(sort -u "$work"/md5-"$b"-* | tr '\n' ' ')"
done
