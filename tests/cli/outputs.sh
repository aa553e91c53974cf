#!/usr/bin/env bash
# Outputs are all or nothing, and `partet check` vouches only for a consistent, complete set:
# a failed publish keeps the previous files; a set mixed from two runs, a garbage .neigh, a
# flipped or missing .face line, an absurd header count, all fail the check.
# Usage: outputs.sh PARTET [LAUNCH...]
set -uo pipefail
partet=$(realpath "$1")
shift
launch=("$@")
source "$(dirname "$0")/../harness.sh"
cd "$work"
"$partet" generate torus --faces 3000 -o torus.off > /dev/null
"$partet" generate sphere --faces 3000 -o sphere.off > /dev/null
"${launch[@]}" "$partet" mesh torus.off -o m --pieces 3 --quiet --report m.json || bad "first run"
mkdir before && cp m.node m.ele m.face m.neigh m.json before/
# The report's input figures survive the input's points being freed before the files are written.
vertices=$(awk 'NR == 2 {print $1}' torus.off)
/usr/bin/python3 - m.json "$vertices" << 'EOF' && ok "report counts the input and estimates each piece" || bad "report's input figures"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["counts"]["input_vertices"] == int(sys.argv[2]), r["counts"]
assert len(r["piece"]) == 3 and all(p["estimated_cost"] > 0 for p in r["piece"]), r["piece"]
EOF
# run_with VAR=VALUE ARGS...: partet ARGS with VAR set (passed on to the ranks under a launcher).
run_with() {
  local assignment=$1
  shift
  if [ ${#launch[@]} -gt 0 ]; then env "$assignment" "${launch[@]}" -x "${assignment%%=*}" "$partet" "$@"
  else env "$assignment" "$partet" "$@"; fi
}
same_as_before() { for f in m.node m.ele m.face m.neigh m.json; do cmp -s "$f" "before/$f" || return 1; done; }
no_temporaries() { ! ls | grep -q '\.tmp-'; }

# 1. A move that fails while publishing (as an immutable file or an I/O error would): the
#    previous set stays, with its report, and nothing temporary is left.
for n in 1 3 5; do
  run_with PARTET_INJECT_PUBLISH_FAILURE=$n mesh torus.off -o m --pieces 4 --quiet --report m.json > log 2>&1 &&
    bad "publish failure $n: exit code 0" ||
    { same_as_before && no_temporaries && grep -q "cannot write" log && ok "publish failure $n keeps the previous set" ||
      bad "publish failure $n: $(cat log)"; }
done 2> /dev/null

# 2. A worker that dies after its last piece, before the agreement: nothing is published.
if [ ${#launch[@]} -gt 0 ]; then
  run_with PARTET_INJECT_FAILURE=worker:abort-before-agreement mesh torus.off -o m --pieces 4 --quiet \
    --report m.json > log 2>&1 && bad "dying worker: exit code 0" ||
    { sleep 1; same_as_before && no_temporaries && ok "a worker dying before the agreement publishes nothing" ||
      bad "dying worker: $(cat log; ls)"; }
fi

# 3. Temporaries a killed run left behind (its process is gone) are removed by the next run on
#    the same prefix; those of a running process are not (tests/cli/other_node.sh: other nodes).
temporaries() { ls | grep -c '\.tmp-'; }
PARTET_TEST_PAUSE_BEFORE_PUBLISH_MS=30000 "$partet" mesh torus.off -o m --pieces 3 --quiet --report m.json &
live=$!
for i in $(seq 200); do [ "$(temporaries)" -ge 5 ] && break; sleep 0.05; done
"${launch[@]}" "$partet" mesh torus.off -o m --pieces 3 --quiet --report m.json
[ "$(ls | grep -c "\.tmp-$live-")" -eq 5 ] && ok "a live run's temporaries are kept" || bad "live temporaries: $(ls)"
kill -KILL "$live"
wait "$live" 2> /dev/null
"${launch[@]}" "$partet" mesh torus.off -o m --pieces 3 --quiet --report m.json
[ "$(temporaries)" -eq 0 ] && ok "a killed run's temporaries are removed by the next run" || bad "stale temporaries: $(ls)"

# 4. check: the intact set passes; each damage is caught.
"$partet" check torus.off m > log 2>&1 && ok "intact set passes" || bad "intact set: $(cat log)"
"$partet" mesh sphere.off -o other --pieces 2 --quiet
expect_check_fails() {  # DESCRIPTION REGEX: the check of m (damaged) fails with the message
  if "$partet" check torus.off m > log 2>&1; then bad "$1: check passed"
  elif grep -Eq "$2" log; then ok "$1: $(grep -Em1 "$2" log)"
  else bad "$1: $(cat log)"; fi
  cp before/m.node before/m.ele before/m.face before/m.neigh .
}
cp other.face m.face
expect_check_fails "a .face from another run" "different runs|face file does not list|out of range"
cp other.neigh m.neigh
expect_check_fails "a .neigh from another run" "different runs|neighbour"
awk 'NR == 3 {$2 = 0; $3 = 0} {print}' before/m.neigh > m.neigh
expect_check_fails "garbage .neigh rows" "rows of the .neigh file differ"
awk 'NR == 2 {t = $2; $2 = $3; $3 = t} {print}' before/m.face > m.face
expect_check_fails "a flipped face" "face file does not list exactly the outward boundary faces"
awk 'NR == 1 {$1 = $1 - 1} NR != 2 {print}' before/m.face | awk 'NR > 1 {$1 = NR - 2} {print}' > m.face
expect_check_fails "a missing face" "boundary faces are missing"
{ echo "2147483647 3 0 0"; tail -n +2 before/m.node; } > m.node
expect_check_fails "an absurd point count" "declares 2147483647 points, more than the file can hold"
{ echo "2147483647 4 0"; tail -n +2 before/m.ele; } > m.ele
expect_check_fails "an absurd tet count" "declares 2147483647 tetrahedra"

summary
