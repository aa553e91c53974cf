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
# One run: prints "model axis k result retries".
run_one() {
  local model=$1 axis=$2 k=$3 out
  # Without its work directory (the sweep was stopped) a run must not write elsewhere.
  out=$(mktemp -d -p "$work") || { echo "$(basename "$model" .off) $axis $k FAIL 0 no work directory"; return; }
  if timeout "${PARTET_TIMEOUT:-600}" "$partet" mesh "$model" -o "$out/m" --pieces "$k" --axis "$axis" \
       --report "$out/r.json" > "$out/log" 2>&1 && "$partet" check "$model" "$out/m" > "$out/check" 2>&1; then
    local used retries
    used=$(python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); print(r["pieces"], len(r["retries"]))' "$out/r.json")
    read -r used retries <<< "$used"
    # Fewer pieces than asked after retries is a fallback; without retries the model allowed no more.
    if [ "$retries" -gt 0 ] && [ "$used" -lt "$k" ]; then echo "$(basename "$model" .off) $axis $k fallback $retries $used"
    else echo "$(basename "$model" .off) $axis $k ok $retries"; fi
  else
    echo "$(basename "$model" .off) $axis $k FAIL 0 $(grep -hE 'error|VIOLATION' "$out/log" "$out/check" | head -1)"
  fi
  rm -rf "$out"
}
export -f run_one
export partet work
for f in "$meshes"/*.off; do
  [ "$(awk 'NR==2 {print $2; exit}' "$f")" -le "$max_faces" ] || continue
  for axis in $axes; do for k in $ks; do echo "$f $axis $k"; done; done
done | xargs -P "$jobs" -n 3 bash -c 'run_one "$@"' _ > "$work/results"
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
