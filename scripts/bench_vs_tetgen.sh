#!/usr/bin/env bash
# Wall time, peak RSS and quality of `tetgen -pYQ` and of `partet mesh` on the same input, in the
# same run. Prints medians over RUNS runs and the ratios against TetGen.
# Usage: bench_vs_tetgen.sh INPUT.off [RUNS] [K...]    (env RANKS="1 2" chooses the rank counts)
set -euo pipefail
source "$(dirname "$0")/common.sh"
input=$(realpath "$1")
runs=${2:-3}
shift 2 2>/dev/null || shift $#
ks=("$@")
[ ${#ks[@]} -eq 0 ] && ks=(2 8)
ranks=(${RANKS:-1 2})
make_work_dir
cp "$input" "$work/input.off"

# Runs a command under GNU time; appends "wall_s rss_mb" to a file.
measure() {
  local out=$1; shift
  /usr/bin/time -f "%e %M" -o "$work/time" "$@" > "$work/log" 2>&1 || { cat "$work/log"; exit 1; }
  awk '{printf "%s %.1f\n", $1, $2/1024}' "$work/time" >> "$out"
}
quality() {  # prefix -> "amips_avg amips_max min_dihedral"
  "$partet" check "$work/input.off" "$1" > "$work/check" || { cat "$work/check"; exit 1; }
  sed -n 's/^quality: AMIPS avg \([^ ]*\) max \([^;]*\); dihedral min \([^ ]*\).*/\1 \2 \3/p' "$work/check"
}

printf "%-26s %10s %10s %12s %10s %10s %9s %9s\n" run wall_s peak_MB tets amips_avg amips_max wall/tg mem/tg
for r in $(seq "$runs"); do (cd "$work" && measure "$work/tetgen.t" tetgen -pYQ input.off); done
tg_wall=$(cut -d' ' -f1 "$work/tetgen.t" | median); tg_mem=$(cut -d' ' -f2 "$work/tetgen.t" | median)
tg_tets=$(head -1 "$work/input.1.ele" | awk '{print $1}')
read -r qa qm qd < <(quality "$work/input.1")
printf "%-26s %10.2f %10.0f %12s %10s %10s %9s %9s\n" "tetgen -pYQ" "$tg_wall" "$tg_mem" "$tg_tets" "$qa" "$qm" 1.00 1.00
for k in "${ks[@]}"; do
  for n in "${ranks[@]}"; do
    launch=()
    [ "$n" -gt 1 ] && launch=(mpirun -np "$n" --oversubscribe --bind-to none)
    rm -f "$work/p.t"
    for r in $(seq "$runs"); do measure "$work/p.t" "${launch[@]}" "$partet" mesh "$work/input.off" -o "$work/out" --pieces "$k" --quiet --report "$work/report.json"; done
    wall=$(cut -d' ' -f1 "$work/p.t" | median); mem=$(cut -d' ' -f2 "$work/p.t" | median)
    # Under mpirun GNU time sees only the launcher; take the largest rank from the report.
    if [ "$n" -gt 1 ]; then
      mem=$(python3 -c "import json;r=json.load(open('$work/report.json'));print(max(max(x['peak_rss_mb'],x['tetgen_process_peak_rss_mb']) for x in r['rank']))")
    fi
    tets=$(head -1 "$work/out.ele" | awk '{print $1}')
    read -r qa qm qd < <(quality "$work/out")
    printf "%-26s %10.2f %10.0f %12s %10s %10s %9.2f %9.2f\n" "partet k=$k np=$n" "$wall" "$mem" "$tets" "$qa" "$qm" \
      "$(awk -v a="$wall" -v b="$tg_wall" 'BEGIN {print a / b}')" "$(awk -v a="$mem" -v b="$tg_mem" 'BEGIN {print a / b}')"
  done
done
