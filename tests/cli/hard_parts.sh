#!/usr/bin/env bash
# Parts that are hard to cut, and bounds that cannot be met (issue 21, classes 3, 7 and 9):
#  - CAD-like thin-wall parts (fins, comb, slots, plates) mesh and pass the check at several piece
#    counts along both axis choices;
#  - when every partition into pieces fails (injected), the input is meshed as one piece, as TetGen
#    alone would, with a warning, and the report says 1 piece;
#  - a quality bound TetGen cannot meet ends within 60 s with exit 1, saying so, without advising
#    other pieces or axes.
# Usage: hard_parts.sh PARTET [LAUNCH...]   (LAUNCH, e.g. "mpiexec -n 2", runs partet mesh under MPI)
set -uo pipefail
partet=$(realpath "$1")
shift
launch=("$@")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
mesh() { "${launch[@]}" "$partet" mesh "$@"; }
report_field() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"; }

# 1. Thin walls: the heat sink (30 fins 1 mm thick at 2 mm pitch), a comb, slots, plates.
"$partet" generate fins --walls 30 --wall 1 --gap 1 -o fins.off > /dev/null || exit 1
"$partet" generate comb --walls 20 --wall 0.5 --gap 1 -o comb.off > /dev/null || exit 1
"$partet" generate slots --walls 12 --wall 2 --gap 0.5 -o slots.off > /dev/null || exit 1
"$partet" generate plates --walls 15 --wall 1 --gap 2 --turn 30 -o plates.off > /dev/null || exit 1
runs=0
for part in fins comb slots plates; do
  for axis in auto pca; do
    for k in 2 5 8 16; do
      runs=$((runs + 1))
      if ! mesh "$part.off" -o "m_${part}" --pieces "$k" --axis "$axis" --check --quiet > log 2>&1; then
        fail "$part --axis $axis --pieces $k: $(head -3 log)"
      elif ! "$partet" check "$part.off" "m_${part}" > check.log 2>&1; then
        fail "$part --axis $axis --pieces $k: partet check: $(grep -m1 -i fail check.log)"
      fi
    done
  done
done
echo "thin walls: $((runs - failures)) of $runs runs meshed and checked"

# 2. Every cut fails: the whole input as one piece, with a warning saying so.
"$partet" generate torus --faces 3000 -o torus.off > /dev/null || exit 1
if ! PARTET_INJECT_FAILURE=cuts mesh torus.off -o one --pieces 4 --report one.json > log 2>&1; then
  fail "every cut failing: no mesh: $(grep -m1 error log)"
else
  [ "$(report_field one.json pieces)" = 1 ] || fail "every cut failing: the report says $(report_field one.json pieces) pieces, not 1"
  grep -q "as one piece, as TetGen alone would" log || fail "every cut failing: no warning about the one-piece fallback"
  "$partet" check torus.off one > check.log 2>&1 || fail "every cut failing: the one-piece mesh fails its check"
fi

# 3. A quality bound TetGen cannot meet (its refinement runs away): a clear failure, soon.
"$partet" generate sphere --faces 1280 -o sphere.off > /dev/null || exit 1
start=$(date +%s)
timeout 120 "${launch[@]}" "$partet" mesh sphere.off -o q -q 1/20 --pieces 4 > log 2>&1
code=$?
elapsed=$(($(date +%s) - start))
[ "$code" = 1 ] || fail "-q 1/20: exit code $code (want 1)"
[ "$elapsed" -le 60 ] || fail "-q 1/20: took $elapsed s (limit 60)"
grep -q "the quality bound 1/20 cannot be met" log || fail "-q 1/20: the message does not say the bound cannot be met: $(grep -m1 error log)"
grep -q -- "try another --pieces" log && fail "-q 1/20: advises other pieces although no partition helps"
ls q.* > /dev/null 2>&1 && fail "-q 1/20: output files written"
echo "-q 1/20: exit $code after $elapsed s"

[ "$failures" -eq 0 ] && echo "hard parts: all passed" || { echo "hard parts: $failures failed"; exit 1; }
