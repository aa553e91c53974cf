#!/usr/bin/env bash
# A valid input meshes at any scale: the same surface scaled by 1e-200 ... 1e200 (and one with
# a far unused vertex) meshes and passes `partet check`, which compares input vertices by their
# exact coordinates. Usage: scales.sh PARTET
set -uo pipefail
partet=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$partet" generate torus --faces 3000 -o "$work/base.off" > /dev/null || exit 1
pass=0 fail=0
for scale in 1e-300 1e-200 1e-100 1e-50 1e-12 1e12 1e75 1e100 1e200 1e300; do
  awk -v s="$scale" 'NR == 2 {n = $1} NR > 2 && NR <= 2 + n {printf "%.17g %.17g %.17g\n", $1 * s, $2 * s, $3 * s; next}
                     {print}' "$work/base.off" > "$work/scaled.off"
  if timeout 120 "$partet" mesh "$work/scaled.off" -o "$work/out" --pieces 4 --quiet > "$work/log" 2>&1 &&
     "$partet" check "$work/scaled.off" "$work/out" > "$work/check" 2>&1; then
    pass=$((pass + 1)); echo "ok   scale $scale: $(tail -1 "$work/check")"
  else
    fail=$((fail + 1)); echo "FAIL scale $scale: $(cat "$work/log" "$work/check" 2> /dev/null | tail -3)"
  fi
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
