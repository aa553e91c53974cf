#!/usr/bin/env bash
# Meshes every model of a directory (up to a face count) at several piece counts and cut axes,
# checks each result and prints a pass/fail table, with the number of retries each needed and
# whether the retries fell back to fewer pieces ("ok+2" two retries; "k4+5": 4 pieces after 5;
# "k1+3": the whole input as one piece, as TetGen alone, after 3).
# Usage: sweep.sh [-p PARTET] [-d MESHES_DIR] [-f MAX_FACES] [-k "K..."] [-a "auto pca"] [-j JOBS]
#   e.g. sweep.sh -f 20000 -k "$(seq -s ' ' 1 32)" -a "auto pca"
set -uo pipefail
source "$(dirname "$0")/common.sh"
meshes=$here/../../shared/meshes max_faces=100000000 ks="1 2 3 4 8" axes=auto jobs=2
while getopts "p:d:f:k:a:j:" opt; do
  case $opt in
    p) partet=$OPTARG ;; d) meshes=$OPTARG ;; f) max_faces=$OPTARG ;; k) ks=$OPTARG ;; a) axes=$OPTARG ;;
    j) jobs=$OPTARG ;; *) sed -n '2,5p' "$0"; exit 2 ;;
  esac
done
make_work_dir
# One run: prints "model axis k ok" and keeps its report as reports/MODEL_AXIS_K.json, or prints
# "model axis k FAIL 0 reason". (The reports are read once at the end: a python3 per run cost a
# third of a second each.)
run_one() {
  local model=$1 axis=$2 k=$3 out name
  name=$(basename "$model" .off)
  # Without its work directory (the sweep was stopped) a run must not write elsewhere.
  out=$(mktemp -d -p "$work") || { echo "$name $axis $k FAIL 0 no work directory"; return; }
  if timeout "${PARTET_TIMEOUT:-600}" "$partet" mesh "$model" -o "$out/m" --pieces "$k" --axis "$axis" \
       --report "$out/r.json" > "$out/log" 2>&1 && "$partet" check "$model" "$out/m" > "$out/check" 2>&1; then
    mv "$out/r.json" "$work/reports/${name}_${axis}_$k.json" && echo "$name $axis $k ok"
  else
    echo "$name $axis $k FAIL 0 $(grep -hE 'error|VIOLATION' "$out/log" "$out/check" | head -1)"
  fi
  rm -rf "$out"
}
export -f run_one
export partet work
mkdir "$work/reports"
for f in "$meshes"/*.off; do
  [ "$(awk 'NR==2 {print $2; exit}' "$f")" -le "$max_faces" ] || continue
  for axis in $axes; do for k in $ks; do echo "$f $axis $k"; done; done
done | xargs -P "$jobs" -n 3 bash -c 'run_one "$@"' _ > "$work/runs"
# Each passed run with its retries, and the pieces it used when the retries fell back to fewer
# than asked ("model axis k fallback retries used"; without retries the model allowed no more).
python3 - "$work/runs" "$work/reports" > "$work/results" << 'EOF'
import json, sys
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) < 4 or f[3] != "ok":
        print(line, end="")
        continue
    r = json.load(open(f"{sys.argv[2]}/{f[0]}_{f[1]}_{f[2]}.json"))
    used, retries = r["pieces"], len(r["retries"])
    print(" ".join(f[:3]), f"fallback {retries} {used}" if retries > 0 and used < int(f[2]) else f"ok {retries}")
EOF
sort -k1,1 -k2,2 -k3,3n "$work/results" > "$work/sorted"
# Table: a row per model and axis, a column per K ("ok", "ok+N" with N retries, or FAIL).
awk -v ks="$ks" 'BEGIN {n = split(ks, k, " "); printf "%-22s %-5s", "model", "axis"; for (i = 1; i <= n; ++i) printf " %5s", "k" k[i]; print ""}
  {key = $1 " " $2; if (!(key in seen)) {seen[key] = 1; order[++m] = key}
   cell[key, $3] = ($4 == "ok") ? ($5 > 0 ? "ok+" $5 : "ok") : ($4 == "fallback") ? "k" $6 "+" $5 : "FAIL"}
  END {for (j = 1; j <= m; ++j) {split(order[j], p, " "); printf "%-22s %-5s", p[1], p[2];
       for (i = 1; i <= n; ++i) printf " %5s", cell[order[j], k[i]]; print ""}}' "$work/sorted"
pass=$(awk '$4 == "ok" || $4 == "fallback"' "$work/sorted" | wc -l)
retried=$(awk '$4 == "ok" && $5 > 0' "$work/sorted" | wc -l)
fell_back=$(awk '$4 == "fallback"' "$work/sorted" | wc -l)
one_piece=$(awk '$4 == "fallback" && $6 == 1' "$work/sorted" | wc -l)
failed=$(awk '$4 == "FAIL"' "$work/sorted" | wc -l)
if [ "$failed" -gt 0 ]; then echo "failures:"; awk '$4 == "FAIL"' "$work/sorted"; fi
echo "$pass passed ($retried after retries with all pieces, $fell_back with fewer pieces, $one_piece of them as one piece), $failed failed"
[ "$failed" -eq 0 ]
