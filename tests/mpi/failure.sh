#!/usr/bin/env bash
# A failure injected into one piece (PARTET_INJECT_FAILURE=PIECE:MODE), in every partition:
#  error: an injected error is final: the whole job ends within 20 s with a non-zero exit code
#         and a message naming the piece, and leaves no output file;
#  abort: the process meshing the piece crashes, as TetGen can: the job must not fail because of
#         a cut. It retries, and since piece 1 crashes in every partition, ends with the input as
#         one piece (as TetGen alone), within 20 s, warning about piece 1, with a mesh that passes
#         the check.
# Usage: failure.sh PARTET MPIEXEC RANKS MODE   (MODE: error | abort)
set -uo pipefail
partet=$1 mpiexec=$2 ranks=$3 mode=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$partet" generate torus --faces 3000 -o "$work/torus.off" >/dev/null || exit 1
start=$(date +%s)
PARTET_INJECT_FAILURE="1:$mode" timeout 60 "$mpiexec" -n "$ranks" --oversubscribe -x PARTET_INJECT_FAILURE \
  "$partet" mesh "$work/torus.off" -o "$work/out" --pieces 4 --report "$work/report.json" > "$work/log" 2>&1
code=$?
elapsed=$(( $(date +%s) - start ))
fail() { echo "FAIL: $*"; cat "$work/log"; exit 1; }
[ "$code" -ne 124 ] || fail "the job hung (killed after 60 s)"
[ "$elapsed" -le 20 ] || fail "took ${elapsed} s (limit 20 s)"
grep -q "piece 1" "$work/log" || fail "no message naming piece 1"
if [ "$mode" = error ]; then
  [ "$code" -ne 0 ] || fail "exit code 0"
  leftovers=$(ls "$work" | grep -v -e '^torus.off$' -e '^log$' || true)
  [ -z "$leftovers" ] || fail "output files left behind: $leftovers"
else
  [ "$code" -eq 0 ] || fail "exit code $code: a crash in one piece must not fail the job"
  pieces=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["pieces"])' "$work/report.json")
  [ "$pieces" = 1 ] || fail "meshed in $pieces pieces, not as one"
  "$partet" check "$work/torus.off" "$work/out" > "$work/check" 2>&1 || fail "the mesh fails its check: $(cat "$work/check")"
fi
echo "ok: exit $code after ${elapsed} s, message: $(grep -m1 'piece 1' "$work/log")"
