#!/usr/bin/env bash
# Benchmark partet against TetGen on the same inputs, in the same run, alternating: for each
# repetition, `tetgen -p<Q>YQ INPUT` once, then `partet mesh` for every K. Prints medians of wall
# time and peak RSS (largest process: a rank or one of its TetGen children), ratios to TetGen,
# tets and AMIPS avg/max; writes OUTDIR/bench.csv and OUTDIR/bench.png (time and memory against K,
# one line per input). Time it on a quiet machine: nothing else may run beside it.
#
# Usage: bench.sh [-r RUNS] [-n RANKS] [-k "K ..."] [-q QUALITY] [-x "ARGS"] [-o OUTDIR] [-t] INPUT...
#   -r  repetitions (default 3)        -n  MPI ranks (default 2; 1 runs without mpirun)
#   -k  piece counts (default "2 4 8") -q  TetGen quality (e.g. 1.414), for both
#   -x  more partet mesh arguments (e.g. --no-heal)
#   -o  output directory (default bench-out)
#   -t  skip TetGen (inputs too large for it); ratios are then left empty
set -euo pipefail
source "$(dirname "$0")/../common.sh"
runs=3 ranks=2 ks="2 4 8" quality="" extra="" outdir=bench-out skip_tetgen=0
while getopts "r:n:k:q:x:o:t" opt; do
  case $opt in
    r) runs=$OPTARG ;; n) ranks=$OPTARG ;; k) ks=$OPTARG ;; q) quality=$OPTARG ;; x) extra=$OPTARG ;; o) outdir=$OPTARG ;;
    t) skip_tetgen=1 ;; *) sed -n '2,15p' "$0"; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[ $# -ge 1 ] || { sed -n '2,15p' "$0"; exit 2; }
mkdir -p "$outdir"
outdir=$(realpath "$outdir")
make_work_dir
launch=()
[ "$ranks" -gt 1 ] && launch=(mpirun -np "$ranks")
tg_switches="-pYQ"
partet_quality=()
if [ -n "$quality" ]; then tg_switches="-pq${quality}YQ"; partet_quality=(--quality "$quality"); fi

# Runs a command under GNU time; prints "wall_s peak_mb".
time_run() {
  timed "$work/time" "$@" > "$work/log" 2>&1 || { cat "$work/log" >&2; return 1; }
  awk '{printf "%s %.1f\n", $1, $2 / 1024}' "$work/time"
}
# "tets amips_avg amips_max" of a mesh.
quality_of() {
  "$partet" check --json "$1" "$2" | python3 -c \
    'import json,sys; r=json.load(sys.stdin); q=r["quality"]; print(r["tets"], q["amips_avg"], q["amips_max"])'
}
# Largest process of a partet run, MB, from its report (under mpirun, GNU time sees the launcher).
largest_process() {
  python3 -c "import json; r=json.load(open('$1')); \
print(max(max(x['peak_rss_mb'], x['tetgen_process_peak_rss_mb']) for x in r['rank']))"
}

csv="$outdir/bench.csv"
echo "input,faces,run,ranks,pieces,wall_s,peak_mb,tets,amips_avg,amips_max,wall_ratio,mem_ratio" > "$csv"
printf "%-24s %-12s %9s %9s %10s %10s %10s %8s %8s\n" input run wall_s peak_MB tets amips_avg amips_max wall/tg mem/tg
for input in "$@"; do
  name=$(basename "$input" .off)
  cp "$input" "$work/$name.off"
  faces=$(awk 'NR==2 {print $2; exit}' "$work/$name.off")
  : > "$work/tg.t"
  for k in $ks; do : > "$work/p$k.t"; done
  for r in $(seq "$runs"); do
    if [ "$skip_tetgen" -eq 0 ]; then (cd "$work" && time_run tetgen $tg_switches "$name.off") >> "$work/tg.t"; fi
    for k in $ks; do
      read -r wall mem < <(time_run "${launch[@]}" "$partet" mesh "$work/$name.off" -o "$work/out_k$k" --pieces "$k" \
        "${partet_quality[@]}" $extra --quiet --report "$work/report_k$k.json")
      [ "$ranks" -gt 1 ] && mem=$(largest_process "$work/report_k$k.json")
      echo "$wall $mem" >> "$work/p$k.t"
    done
  done
  tg_wall="" tg_mem=""
  if [ "$skip_tetgen" -eq 0 ]; then
    tg_wall=$(cut -d' ' -f1 "$work/tg.t" | median)
    tg_mem=$(cut -d' ' -f2 "$work/tg.t" | median)
    read -r tets qa qm < <(quality_of "$work/$name.off" "$work/$name.1")
    printf "%-24s %-12s %9.2f %9.0f %10s %10.4g %10.4g %8s %8s\n" "$name" "tetgen" "$tg_wall" "$tg_mem" "$tets" "$qa" "$qm" 1 1
    echo "$name,$faces,tetgen,1,1,$tg_wall,$tg_mem,$tets,$qa,$qm,1,1" >> "$csv"
  fi
  for k in $ks; do
    wall=$(cut -d' ' -f1 "$work/p$k.t" | median)
    mem=$(cut -d' ' -f2 "$work/p$k.t" | median)
    read -r tets qa qm < <(quality_of "$work/$name.off" "$work/out_k$k")
    wr="" mr=""
    if [ -n "$tg_wall" ]; then
      wr=$(awk -v a="$wall" -v b="$tg_wall" 'BEGIN {printf "%.3f", a / b}')
      mr=$(awk -v a="$mem" -v b="$tg_mem" 'BEGIN {printf "%.3f", a / b}')
    fi
    printf "%-24s %-12s %9.2f %9.0f %10s %10.4g %10.4g %8s %8s\n" "$name" "partet k=$k" "$wall" "$mem" "$tets" "$qa" "$qm" \
      "$wr" "$mr"
    echo "$name,$faces,partet,$ranks,$k,$wall,$mem,$tets,$qa,$qm,$wr,$mr" >> "$csv"
  done
  rm -f "$work/$name".1.* "$work"/out_k*
done
/usr/bin/python3 "$here/bench/bench_table.py" "$csv" > "$outdir/bench.md"
echo "wrote $csv and $outdir/bench.md (the README's table)"
# The plot uses Debian's python3 and python3-matplotlib (a python3 earlier on PATH may lack it).
if ! /usr/bin/python3 -c "import matplotlib" 2>/dev/null; then
  echo "installing python3-matplotlib for the plot"
  sudo=""; [ "$(id -u)" -ne 0 ] && sudo=sudo
  $sudo apt-get install -y -qq --no-install-recommends python3-matplotlib > /dev/null
fi
/usr/bin/python3 "$here/bench/plot_bench.py" "$csv" "$outdir/bench.png" && echo "wrote $outdir/bench.png"
