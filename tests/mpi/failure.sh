#!/usr/bin/env bash
# A failure injected into one piece (PARTET_INJECT_FAILURE=PIECE:MODE) must end the whole job
# within 20 s with a non-zero exit code and a message naming the piece, and leave no output file.
# Usage: failure.sh PARTET MPIEXEC RANKS MODE   (MODE: error | abort)
set -uo pipefail
partet=$1 mpiexec=$2 ranks=$3 mode=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$partet" generate torus --faces 3000 -o "$work/torus.off" >/dev/null || exit 1
start=$(date +%s)
PARTET_INJECT_FAILURE="1:$mode" timeout 60 "$mpiexec" -n "$ranks" --oversubscribe -x PARTET_INJECT_FAILURE \
  "$partet" mesh "$work/torus.off" -o "$work/out" --pieces 4 > "$work/log" 2>&1
code=$?
elapsed=$(( $(date +%s) - start ))
fail() { echo "FAIL: $*"; cat "$work/log"; exit 1; }
[ "$code" -ne 0 ] || fail "exit code 0"
[ "$code" -ne 124 ] || fail "the job hung (killed after 60 s)"
[ "$elapsed" -le 20 ] || fail "took ${elapsed} s (limit 20 s)"
grep -q "piece 1" "$work/log" || fail "no message naming piece 1"
leftovers=$(ls "$work" | grep -v -e '^torus.off$' -e '^log$' || true)
[ -z "$leftovers" ] || fail "output files left behind: $leftovers"
echo "ok: exit $code after ${elapsed} s, message: $(grep -m1 'piece 1' "$work/log")"
