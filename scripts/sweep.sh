#!/usr/bin/env bash
# Meshes every model in a directory at several piece counts, checks each result and prints a
# pass/fail table. Usage: sweep.sh [PARTET] [MESHES_DIR] [MAX_FACES] [K...]
set -uo pipefail
source "$(dirname "$0")/common.sh"
partet=${1:-$partet}
meshes=${2:-$here/../../shared/meshes}
max_faces=${3:-100000000}
shift 3 2>/dev/null || shift $#
ks=("$@")
[ ${#ks[@]} -eq 0 ] && ks=(1 2 3 4 8)
out=$(mktemp -d)
pass=0 fail=0
printf "%-28s %8s" model faces
for k in "${ks[@]}"; do printf " %6s" "k=$k"; done
echo
for f in "$meshes"/*.off; do
  faces=$(awk 'NR==2 {print $2; exit}' "$f")
  [ "$faces" -le "$max_faces" ] || continue
  printf "%-28s %8s" "$(basename "$f")" "$faces"
  for k in "${ks[@]}"; do
    if "$here/mesh_and_check.sh" "$partet" "$f" "$k" "$out" > "$out/log" 2>&1 && grep -q "check passed" "$out/log"; then
      printf " %6s" ok; pass=$((pass + 1))
    else
      printf " %6s" FAIL; fail=$((fail + 1))
      echo "$(basename "$f") k=$k: $(grep -E 'error|VIOLATION' "$out/log" | head -1)" >> "$out/failures"
    fi
  done
  echo
done
[ -f "$out/failures" ] && { echo "failures:"; cat "$out/failures"; }
rm -rf "$out"
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
