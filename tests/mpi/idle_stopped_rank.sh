#!/usr/bin/env bash
# A worker stopped (SIGSTOP) while idle, between pieces: rank 0's next piece is larger than MPI's
# eager limit, so sending it waits for the worker. The job must still end within the piece time
# limit plus the grace period, naming the rank, with a non-zero exit code and no output files.
# Usage: idle_stopped_rank.sh PARTET MPIEXEC
set -uo pipefail
partet=$1 mpiexec=$2
work=$(mktemp -d)
trap 'kill -CONT $(pgrep -f "$work/torus.off") 2>/dev/null; rm -rf "$work"' EXIT
"$partet" generate torus --faces 60000 -o "$work/torus.off" > /dev/null || exit 1
start=$(date +%s)
PARTET_INJECT_FAILURE=worker:stop-when-idle timeout 120 "$mpiexec" -n 2 -x PARTET_INJECT_FAILURE \
  "$partet" mesh "$work/torus.off" -o "$work/out" --pieces 24 --piece-timeout 2 > "$work/log" 2>&1
code=$?
elapsed=$(( $(date +%s) - start ))
fail() { echo "FAIL: $*"; cat "$work/log"; exit 1; }
[ "$code" -ne 0 ] || fail "exit code 0"
[ "$code" -ne 124 ] || fail "the job hung (killed after 120 s)"
[ "$elapsed" -le 40 ] || fail "took ${elapsed} s (limit 40 s)"
grep -q "rank 1 has not answered" "$work/log" || fail "no message naming rank 1"
ls "$work"/out.* > /dev/null 2>&1 && fail "output files left: $(ls "$work"/out.*)"
echo "ok: exit $code after ${elapsed} s: $(grep -m1 'rank 1 has' "$work/log")"
