#!/usr/bin/env bash
# Each rank's memory in one mesh run, for one or more partet binaries run one after another on the
# same input: rank 0's resident memory after each stage, every rank's own peak and its largest
# TetGen child's (which counts the pages it shares with its rank), rank 0's peak in bytes per
# input face, the machine's peak use (`free`, sampled each second, minus what it used before),
# and the md5 of all the files written (the binaries must write the same bytes). With -c each output is verified
# too: `partet check` on the TetGen files, and with xdmf among the formats `mpirun partet check`
# on the XDMF set (each rank its part) and xdmf_readback.py (meshio reads it back: the same
# points and tets as the TetGen files); wall time and peak memory of each. Figures, not a test:
# run it on a quiet machine.
#
# Usage: rank_memory.sh [-n RANKS] [-k K] [-f FORMATS] [-c] [-o DIR] INPUT BINARY [BINARY ...]
#   -n  MPI ranks (default 2)   -k  pieces (default 16)   -f  --format list (default tetgen)
#   -c  verify each output      -o  keep the reports there (rB.json)
#   A BINARY may carry mesh options after it, in one word: "partet --scratch /tmp/s".
set -euo pipefail
source "$(dirname "$0")/../common.sh"
ranks=2 k=16 keep="" formats=tetgen verify=0
while getopts "n:k:f:co:" opt; do
  case $opt in
    n) ranks=$OPTARG ;; k) k=$OPTARG ;; f) formats=$OPTARG ;; c) verify=1 ;; o) keep=$OPTARG ;;
    *) sed -n '2,16p' "$0"; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[ $# -ge 2 ] || { sed -n '2,16p' "$0"; exit 2; }
input=$1
shift
make_work_dir

used_mb() { free -m | awk '/^Mem:/ {print $3}'; }

# verify_output BINARY PREFIX: the checks of -c, each with its wall time and peak (GNU time).
verify_output() {
  local binary=$1 prefix=$2
  if [[ ",$formats," == *,tetgen,* ]]; then
    timed "$work/t" "$binary" check "$input" "$prefix" > "$work/check.log" 2>&1 || { cat "$work/check.log"; echo "  CHECK FAILED"; }
    echo "  partet check (TetGen files): $(tail -1 "$work/check.log" | cut -c1-100); $(awk '{printf "%.1f s, %.0f MB", $1, $2 / 1024}' "$work/t")"
  fi
  [[ ",$formats," == *,xdmf,* ]] || return 0
  timed "$work/t" mpirun -np "$ranks" "$binary" check "$input" "$prefix.xdmf" > "$work/check.log" 2>&1 ||
    { cat "$work/check.log"; echo "  CHECK FAILED"; }
  echo "  mpirun -np $ranks partet check (XDMF): $(tail -1 "$work/check.log" | cut -c1-100); $(awk '{printf "%.1f s", $1}' "$work/t")"
  [[ ",$formats," == *,tetgen,* ]] || return 0  # the readback compares the set with the TetGen files
  timed "$work/t" /usr/bin/python3 "$here/bench/xdmf_readback.py" "$prefix" | sed 's/^/  /' || echo "  READBACK FAILED"
  echo "  (readback $(awk '{printf "%.1f s, %.0f MB", $1, $2 / 1024}' "$work/t"))"
}

for ((b = 1; b <= $#; b++)); do
  read -ra command <<< "${!b}"
  binary=${command[0]}
  mkdir -p "$work/out$b"
  before=$(used_mb)
  (while true; do used_mb; sleep 1; done) > "$work/free$b" &
  sampler=$!
  mpirun -np "$ranks" "$binary" mesh "$input" -k "$k" -o "$work/out$b/m" --format "$formats" --quiet --report "$work/r$b.json" \
    "${command[@]:1}"
  kill "$sampler"
  wait "$sampler" 2>/dev/null || true
  machine=$(sort -n "$work/free$b" | tail -1)
  md5=$(cd "$work/out$b" && md5sum $(ls | sort) | md5sum | cut -c1-12)  # every file written
  /usr/bin/python3 - "$work/r$b.json" "$(basename "$binary") ${command[*]:1}" "$((machine - before))" "$md5" <<'EOF'
import json, sys
r = json.load(open(sys.argv[1]))
faces = r["counts"]["input_faces"]
order = "read validate partition input_check_wait closure tetgen merge seam_healing polish check write".split()
stages = [(s, r["stage_rss_mb"][s]) for s in order if s in r["stage_rss_mb"]]
print(f"{sys.argv[2]}: {faces} faces, {r['counts']['output_tets']} tets, {r['total_seconds']:.1f} s, md5 {sys.argv[4]}")
print("  rank 0 after each stage (MB): " + ", ".join(f"{s} {mb:.0f}" for s, mb in stages))
for rank in r["rank"]:
    print(f"  rank {rank['rank']}: own peak {rank['peak_rss_mb']:.0f} MB, largest TetGen child {rank['tetgen_process_peak_rss_mb']:.0f} MB, pieces {len(rank['pieces'])}")
peak0 = r["rank"][0]["peak_rss_mb"]
print(f"  rank 0's own peak: {peak0 * 2**20 / faces:.0f} bytes per input face; machine's peak use {sys.argv[3]} MB above its use before the run")
EOF
  [ "$verify" = 0 ] || verify_output "$binary" "$work/out$b/m"
  rm -rf "$work/out$b"
done
if [ -n "$keep" ]; then mkdir -p "$keep" && cp "$work"/r*.json "$keep"/; fi
