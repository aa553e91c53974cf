#!/usr/bin/env bash
# A piece killed from outside, as the out-of-memory killer kills a process that needs more than
# the node (or a Slurm job's cgroup) has: PARTET_TEST_PIECE_MEMORY_FACES=N makes the process
# meshing a piece of more than N triangles kill itself with SIGKILL. The run must not move planes
# or try fewer pieces (each would need as much memory or more): it doubles the pieces along the
# same axis, so it recovers when smaller pieces fit, and it stops after 4 times the pieces asked
# for, saying what to do, when none fit. One process and 2 ranks.
# Usage: piece_out_of_memory.sh PARTET MPIEXEC
set -uo pipefail
partet=$1 mpiexec=$2
source "$(dirname "$0")/../harness.sh"
cd "$work"
"$partet" generate sphere --faces 20000 -o s.off > /dev/null
for n in 1 2; do
  launch=("$mpiexec" -n $n --oversubscribe -x PARTET_TEST_PIECE_MEMORY_FACES)
  # 1. Pieces of 2 are killed, pieces of 4 fit: one retry, with 4 pieces, and a mesh that passes its check.
  rm -f m.* r.json
  PARTET_TEST_PIECE_MEMORY_FACES=8000 timeout 120 "${launch[@]}" "$partet" mesh s.off -k 2 --check -o m --report r.json > a.log 2>&1
  code=$?
  pieces=$(python3 -c 'import json; print(json.load(open("r.json"))["pieces"])' 2> /dev/null)
  if [ $code != 0 ]; then bad "$n rank(s), smaller pieces fit: exit $code: $(tail -n 3 a.log)"
  elif ! grep -q "signal 9: killed from outside, most often by the out-of-memory killer.*most likely out of memory: using 4 pieces instead of 2" a.log; then
    bad "$n rank(s), smaller pieces fit: no retry with 4 pieces: $(grep -m 2 'attempt' a.log)"
  elif [ "$(grep -c 'attempt .* failed' a.log)" != 1 ]; then bad "$n rank(s), smaller pieces fit: $(grep -c 'attempt .* failed' a.log) failed attempts, not 1"
  elif [ "$pieces" != 4 ] || ! grep -q "check passed" a.log; then bad "$n rank(s), smaller pieces fit: pieces '$pieces', $(grep -m 1 check a.log)"
  else ok "$n rank(s), pieces of 2 killed: recovered with 4 pieces in one retry, check passed"; fi
  # 2. No piece fits, however small (up to 4 x 2 pieces): the run stops after 2 retries, saying so,
  # and writes nothing.
  rm -f m.* r.json
  PARTET_TEST_PIECE_MEMORY_FACES=1000 timeout 120 "${launch[@]}" "$partet" mesh s.off -k 2 -o m > b.log 2>&1
  code=$?
  if [ $code = 0 ] || [ $code = 124 ]; then bad "$n rank(s), no piece fits: exit $code: $(tail -n 3 b.log)"
  elif ! grep -q "error: .*out-of-memory killer.*more --pieces make each smaller) (with 8 pieces)" b.log; then
    bad "$n rank(s), no piece fits: $(grep -m 1 error b.log)"
  elif [ "$(grep -c 'attempt .* failed' b.log)" != 2 ]; then bad "$n rank(s), no piece fits: $(grep -c 'attempt .* failed' b.log) failed attempts, not 2"
  elif ls m.* > /dev/null 2>&1; then bad "$n rank(s), no piece fits: left $(ls m.*)"
  else ok "$n rank(s), no piece fits: stopped after 2, 4 and 8 pieces, exit $code, naming the out-of-memory killer"; fi
done
summary
