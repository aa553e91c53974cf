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
ls "$work"/stopped.* > /dev/null 2>&1 && fail "output files left: $(ls "$work"/stopped.*)"
echo "ok: stalls within the wall time changed nothing (one process and $ranks ranks); past it: exit $code after" \
  "${elapsed} s: $(grep -m1 -F "$expected" "$work/log")"
