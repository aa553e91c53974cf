#!/usr/bin/env bash
# A stopped (SIGSTOP) worker must not hang the job: rank 0 ends it within the piece time limit
# plus a grace period, naming the rank, with a non-zero exit code and no output files.
#   meshing: rank 1 is stopped from outside while it works;
#   idle:    rank 1 stops itself between pieces (PARTET_INJECT_FAILURE=worker:stop-when-idle), so
#            rank 0's next piece, larger than MPI's eager limit, waits for someone to take it.
#   verdict: rank 1 stops itself after checking the input, before reporting it
#            (worker:stop-before-verdict); rank 0 waits for that verdict before the first piece,
#            for PARTET_TEST_VERDICT_WAIT_S (3 s here; 120 s + 1 s per million faces normally).
# Usage: stopped_rank.sh PARTET MPIEXEC [meshing|idle|verdict]
set -uo pipefail
partet=$1 mpiexec=$2 mode=${3:-meshing}
work=$(mktemp -d)
trap 'kill -CONT $(pgrep -f "$work/torus.off") 2>/dev/null; rm -rf "$work"' EXIT
"$partet" generate torus --faces 60000 -o "$work/torus.off" > /dev/null || exit 1
inject=()
[ "$mode" = idle ] && inject=(-x PARTET_INJECT_FAILURE) && export PARTET_INJECT_FAILURE=worker:stop-when-idle
if [ "$mode" = verdict ]; then
  inject=(-x PARTET_INJECT_FAILURE -x PARTET_TEST_VERDICT_WAIT_S)
  export PARTET_INJECT_FAILURE=worker:stop-before-verdict PARTET_TEST_VERDICT_WAIT_S=3
fi
start=$(date +%s)
timeout 120 "$mpiexec" -n 2 "${inject[@]}" "$partet" mesh "$work/torus.off" -o "$work/out" --pieces 24 \
  --piece-timeout 2 > "$work/log" 2>&1 &
launcher=$!
if [ "$mode" = meshing ]; then
  # Stop rank 1 while it works.
  rank1=""
  for i in $(seq 100); do
    for pid in $(pgrep -f "mesh $work/torus.off"); do
      if tr '\0' '\n' < "/proc/$pid/environ" 2> /dev/null | grep -qx "OMPI_COMM_WORLD_RANK=1"; then rank1=$pid; break; fi
    done
    [ -n "$rank1" ] && break
    sleep 0.05
  done
  [ -n "$rank1" ] || { echo "FAIL: rank 1 not found"; cat "$work/log"; exit 1; }
  sleep 0.5
  kill -STOP "$rank1"
fi
wait "$launcher"
code=$?
elapsed=$(( $(date +%s) - start ))
fail() { echo "FAIL: $*"; cat "$work/log"; exit 1; }
[ "$code" -ne 0 ] || fail "exit code 0"
[ "$code" -ne 124 ] || fail "the job hung (killed after 120 s)"
[ "$elapsed" -le 40 ] || fail "took ${elapsed} s (limit 40 s)"
expected="rank 1 has not answered"
[ "$mode" = verdict ] && expected="rank 1 has not reported its check of the input within 3 s"
grep -q "$expected" "$work/log" || fail "no message naming rank 1"
ls "$work"/out.* > /dev/null 2>&1 && fail "output files left: $(ls "$work"/out.*)"
echo "ok ($mode): exit $code after ${elapsed} s: $(grep -m1 'rank 1 has' "$work/log")"
