#!/usr/bin/env bash
# A piece's time limit counts CPU time, so a run starved of its cores (a neighbouring job, more
# ranks than cores) gives the same mesh as one that is not, and a rank waiting for a starved piece
# is not taken for a dead one. PARTET_INJECT_FAILURE=1:stall makes the process meshing piece 1
# sleep PARTET_TEST_STALL_S seconds first: wall time passes, no CPU time, as for a process that
# gets no core.
#   - stalled 2.5 s with --piece-timeout 1 (1 s of CPU time, 4 s of wall time): the job succeeds,
#     in one process and on RANKS ranks, with the same files as without the stall and no retry;
#   - stalled 6 s, past the wall time (one attempt only): the job fails within a bounded time,
#     naming piece 1 and saying why, and leaves no output file.
# Usage: starved_piece.sh PARTET MPIEXEC RANKS
set -uo pipefail
. "$(dirname "$0")/unchanged_run.sh"
partet=$1 mpiexec=$2 ranks=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; cat "$work/log" 2> /dev/null; exit 1; }
"$partet" generate torus --faces 3000 -o "$work/torus.off" > /dev/null || exit 1
# mesh NAME STALL_SECONDS [partet options]: meshes into $work/NAME, under the launcher when one is
# set, logging to $work/log.
launcher=()
mesh() {
  local name=$1 stall=$2
  shift 2
  PARTET_INJECT_FAILURE=1:stall PARTET_TEST_STALL_S=$stall timeout 120 "${launcher[@]}" "$partet" mesh \
    "$work/torus.off" -o "$work/$name" --pieces 4 --piece-timeout 1 --report "$work/$name.json" "$@" > "$work/log" 2>&1
}
on_ranks=("$mpiexec" -n "$ranks" --oversubscribe -x PARTET_INJECT_FAILURE -x PARTET_TEST_STALL_S)

mesh ref 0 || fail "the run without a stall failed"
for run in one ranks; do
  launcher=()
  [ "$run" = one ] || launcher=("${on_ranks[@]}")
  start=$(date +%s%N)
  mesh "$run" 2.5 || fail "$run: a piece stalled 2.5 s of its 4 s of wall time failed the job"
  elapsed_ms=$(( ($(date +%s%N) - start) / 1000000 ))
  [ "$elapsed_ms" -ge 2500 ] || fail "$run: took $elapsed_ms ms: the stall did not happen"
  problem=$(unchanged_run "$work" ref "$run") || fail "$problem (ref: the run without the stall)"
done

launcher=("${on_ranks[@]}")
start=$(date +%s)
mesh stopped 6 --max-attempts 1
code=$?
elapsed=$(( $(date +%s) - start ))
[ "$code" -ne 0 ] || fail "a piece stalled past its wall time: exit code 0"
[ "$code" -ne 124 ] || fail "the job hung (killed after 120 s)"
[ "$elapsed" -le 30 ] || fail "took ${elapsed} s (limit 30 s)"
expected="piece 1: meshing did not finish within 4 s, having used 0.0 of its 1 s of CPU time: its process was stopped, or the machine is overloaded"
grep -qF "$expected" "$work/log" || fail "no message '$expected'"
grep -qF -- "--piece-timeout gives each piece more CPU time" "$work/log" || fail "no advice to give it more time"
ls "$work"/stopped.* > /dev/null 2>&1 && fail "output files left: $(ls "$work"/stopped.*)"

# A limit too short for the input as one piece (about 1 s of CPU time here): said as such, with
# the advice to give it more time, not to split faces.
"$partet" mesh "$work/torus.off" -o "$work/short" --pieces 1 --piece-timeout 0.2 > "$work/short.log" 2>&1
short=$?
[ "$short" -ne 0 ] || fail "0.2 s of CPU time was enough for the input as one piece"
# (On a loaded machine its 0.8 s of wall time may end it first: the same message, with the reason.)
grep -q "the input as one piece (as TetGen alone would mesh it) did not finish: meshing did not finish within .*0.2 s \
of CPU time.*; --piece-timeout gives each piece more CPU time$" "$work/short.log" ||
  fail "the message for the input out of time: $(cat "$work/short.log")"
! grep -q "allow-split-faces\|no partition can help" "$work/short.log" || fail "split faces advised for a time limit"
echo "ok: stalls within the wall time changed nothing (one process and $ranks ranks); past it: exit $code after" \
  "${elapsed} s: $(grep -m1 -F "$expected" "$work/log"); too short for the input: $(grep -m1 error: "$work/short.log")"
