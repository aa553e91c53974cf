#!/usr/bin/env bash
# Runs `mpirun -np N partet mesh ...` and samples, every 0.5 s, the CPU time (utime + stime from
# /proc/PID/stat) of every rank process and of every TetGen child process: a waiting rank must
# use no CPU. Prints a table of CPU % per sample and the totals.
# Usage: rank_cpu.sh RANKS INPUT K [extra partet mesh options...]
set -euo pipefail
source "$(dirname "$0")/../common.sh"
ranks=$1 input=$2 k=$3
shift 3
make_work_dir
mpirun -np "$ranks" "$partet" mesh "$input" -o "$work/out" --pieces "$k" --quiet "$@" &
launcher=$!
ticks=$(getconf CLK_TCK)
declare -A last
cpu_of() { awk '{print $14 + $15}' "/proc/$1/stat" 2>/dev/null || true; }
# Rank processes: partet processes whose parent is not partet; children: parent is partet.
classify() {
  for pid in $(pgrep -x partet); do
    parent=$(awk '{print $4}' "/proc/$pid/stat" 2>/dev/null) || continue
    if [ "$(cat "/proc/$parent/comm" 2>/dev/null)" = partet ]; then echo "child:$pid"; else echo "rank:$pid"; fi
  done
}
printf "%6s  %s\n" time "process CPU % over the last 0.5 s"
start=$(date +%s.%N)
previous=$start
while kill -0 "$launcher" 2> /dev/null; do
  sleep 0.5
  now=$(date +%s.%N)
  line=""
  for entry in $(classify); do
    kind=${entry%%:*} pid=${entry#*:}
    cpu=$(cpu_of "$pid")
    [ -n "$cpu" ] || continue  # ended between the listing and the reading
    prev=${last[$pid]:-$cpu}
    last[$pid]=$cpu
    pct=$(awk -v c="$cpu" -v p="$prev" -v t="$ticks" -v dt="$(echo "$now - $previous" | bc)" \
      'BEGIN {printf "%.0f", 100 * (c - p) / t / dt}')
    line+=" $kind $pid ${pct}%;"
  done
  previous=$now
  printf "%6.1f %s\n" "$(echo "$now - $start" | bc)" "$line"
done
wait "$launcher"
echo "CPU seconds of each process up to its last sample:"
for pid in "${!last[@]}"; do echo "  $pid: $(awk -v c="${last[$pid]}" -v t="$ticks" 'BEGIN {printf "%.2f", c / t}') s"; done
