#!/usr/bin/env bash
# A stopped (SIGSTOP) worker must not hang the job: rank 0 ends it within the piece's wall time
# limit (4 x --piece-timeout) plus a grace period, naming the rank, with a non-zero exit code and no output files.
#   meshing: rank 1 is stopped from outside while it works: as soon as it has finished its
#            first piece (so neither during the input check, the verdict mode's case, nor after
#            the job's end, on however fast or busy a host);
#   idle:    rank 1 stops itself between pieces (PARTET_INJECT_FAILURE=worker:stop-when-idle), so
#            rank 0's next piece, larger than MPI's eager limit, waits for someone to take it.
#   verdict: rank 1 stops itself after checking the input, before reporting it
#            (worker:stop-before-verdict); rank 0 waits for that verdict before the first piece,
#            for PARTET_TEST_VERDICT_WAIT_S (3 s here; normally 120 s + 1 s per million faces),
#            on 2 ranks no longer than that (only with other checking ranks, twice).
#   share:   4 ranks; rank 2 stops itself after checking its share of the input, before sending
#            its findings to rank 1 (worker:stop-before-findings). Rank 1 must name rank 2 (after
#            3 s), before rank 0's longer wait could blame rank 1.
#   share-oom: 4 ranks; rank 2 runs out of memory checking its share (worker:share-out-of-memory):
#            the job ends at once with rank 2's own message.
#   cap:     rank 1 stops itself when it is given a cap (worker:stop-on-cap): rank 0 must name
#            it and the cap's plane within the piece's wall time limit plus the grace period.
#   silent:  rank 1 stops itself once it has said its first piece's TetGen process is at work
#            (worker:stop-while-meshing), with the default piece limits (over 80 s here): rank 0
#            must name it once its heartbeats have stopped for PARTET_TEST_SILENCE_S (3 s here;
#            normally 60 s), long before the piece's limit.
#   chain:   rank 1 stops itself once it has said it heals the chain of the seams it was given
#            (worker:stop-on-chain; a chain's deadline moves on with its heartbeats): rank 0
#            must name it and the chain once its heartbeats have stopped for 3 s.
#   grow:    rank 1 stops itself when rank 0 gives it a band to grow with a bulk it keeps
#            (worker:stop-on-grow; thin pieces, whose neighbours' bands reach into their bulks):
#            rank 0 must name it and the piece after PARTET_TEST_WORKER_S (3 s here; normally 120 s).
#   take:    with --check (the mesh assembled in memory to be checked), rank 1 stops itself when
#            rank 0 takes back a bulk it keeps (worker:stop-on-take): named with the piece after 3 s.
#   links:   the mesh left spread (no --check), rank 1 stops itself when rank 0 asks for the links
#            of the bulks it keeps (worker:stop-on-links, for TetGen's .neigh): named after 3 s.
#   shares:  rank 1 stops itself when rank 0 asks it to cut the seam chains' shares of the band
#            parts it keeps (worker:stop-on-shares): named with the chain after 3 s. Two pieces,
#            one chain: rank 1 meshes the first piece, so rank 0's first chain needs its share.
#   peer-shares: the same on 3 ranks with many chains, some healed by rank 2, which waits for
#            rank 1's shares straight from rank 1: rank 2 (or rank 0, for a chain of its own, or
#            for one it cannot hand rank 1) must name rank 1 and the chain after 3 s.
#   write:   --format xdmf over an earlier set at the same prefix; rank 1 stops itself as it joins
#            the parallel HDF5 write (worker:stop-on-write), which no wait of rank 0's can bound:
#            rank 0's watch over the write must end the job once a step has not ended for
#            PARTET_TEST_COLLECTIVE_S (3 s here; normally an hour), and the earlier set must stay
#            whole, with no temporary left beside it.
# Usage: stopped_rank.sh PARTET MPIEXEC [meshing|idle|verdict|share|share-oom|cap|silent|chain|grow|take|links|shares|peer-shares|write]
set -uo pipefail
partet=$1 mpiexec=$2 mode=${3:-meshing}
work=$(mktemp -d)
trap 'kill -CONT $(pgrep -f "$work/torus.off") 2>/dev/null; rm -rf "$work"' EXIT
"$partet" generate torus --faces 60000 -o "$work/torus.off" > /dev/null || exit 1
# The fault each mode injects; the input check's modes shorten its waits (rank 1 waits 3 s for
# the other checking ranks; rank 0 3 s for rank 1's verdict on 2 ranks, 6 s on 4).
inject=() ranks=(-n 2) fault="" check_waits=0 limits=(--piece-timeout 2) check=() pieces=24 formats=()
case $mode in
  idle) fault=worker:stop-when-idle ;;
  cap) fault=worker:stop-on-cap ;;
  verdict) fault=worker:stop-before-verdict check_waits=1 ;;
  share) fault=worker:stop-before-findings check_waits=1 ranks=(-n 4 --oversubscribe) ;;
  share-oom) fault=worker:share-out-of-memory check_waits=1 ranks=(-n 4 --oversubscribe) ;;
  silent) fault=worker:stop-while-meshing limits=() ;;
  chain) fault=worker:stop-on-chain limits=() ;;
  grow) fault=worker:stop-on-grow limits=() ;;
  take) fault=worker:stop-on-take limits=() check=(--check) ;;
  links) fault=worker:stop-on-links limits=() ;;
  shares) fault=worker:stop-on-shares limits=() pieces=2 ;;
  peer-shares) fault=worker:stop-on-shares limits=() ranks=(-n 3 --oversubscribe) ;;
  write) fault=worker:stop-on-write limits=() formats=(--format xdmf) pieces=8 ;;
esac
if [ "$mode" = write ]; then  # the earlier set the failed run must leave as it was
  "$mpiexec" -n 2 "$partet" mesh "$work/torus.off" -o "$work/out" --pieces 4 --quiet "${formats[@]}" ||
    { echo "FAIL: the earlier set was not written"; exit 1; }
  before=$(cd "$work" && ls -A | grep -v '^torus.off$' | xargs sha256sum)
fi
[ -z "$fault" ] || { export PARTET_INJECT_FAILURE=$fault; inject+=(-x PARTET_INJECT_FAILURE); }
[ "$check_waits" = 0 ] || { export PARTET_TEST_VERDICT_WAIT_S=3; inject+=(-x PARTET_TEST_VERDICT_WAIT_S); }
[[ $mode != silent && $mode != chain ]] || { export PARTET_TEST_SILENCE_S=3; inject+=(-x PARTET_TEST_SILENCE_S); }
[[ $mode != grow && $mode != take && $mode != links && $mode != *shares ]] || { export PARTET_TEST_WORKER_S=3; inject+=(-x PARTET_TEST_WORKER_S); }
[ "$mode" != write ] || { export PARTET_TEST_COLLECTIVE_S=3; inject+=(-x PARTET_TEST_COLLECTIVE_S); }
start=$(date +%s)
timeout 120 "$mpiexec" "${ranks[@]}" "${inject[@]}" "$partet" mesh "$work/torus.off" -o "$work/out" --pieces "$pieces" \
  "${limits[@]}" "${check[@]}" "${formats[@]}" > "$work/log" 2>&1 &
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
  for i in $(seq 1500); do
    grep -q "on rank 1)" "$work/log" && break
    sleep 0.02
  done
  grep -q "on rank 1)" "$work/log" || { echo "FAIL: rank 1 finished no piece"; cat "$work/log"; exit 1; }
  kill -STOP "$rank1"
fi
wait "$launcher"
code=$?
elapsed=$(( $(date +%s) - start ))
fail() { echo "FAIL: $*"; cat "$work/log"; exit 1; }
[ "$code" -ne 0 ] || fail "exit code 0"
[ "$code" -ne 124 ] || fail "the job hung (killed after 120 s)"
[ "$elapsed" -le 40 ] || fail "took ${elapsed} s (limit 40 s)"
case $mode in
  verdict) expected="rank 1 has not reported its check of the input within 3 s" ;;
  share) expected="rank 2 has not reported its share of the input check within 3 s" ;;
  share-oom) expected="rank 2 ran out of memory" ;;
  cap) expected="rank 1 has not answered for the cap of plane 0" ;;
  silent) expected="rank 1 has not been heard from for 3 s while meshing piece" ;;
  chain) expected="rank 1 has not been heard from for 3 s while healing seam chain" ;;
  grow) expected="rank 1 did not grow the band of piece [0-9]+ within 3 s" ;;
  take) expected="rank 1 did not send the mesh of piece [0-9]+ it kept within 3 s" ;;
  links) expected="rank 1 did not send the links of the bulks it keeps within 3 s" ;;
  shares) expected="rank 1 did not send its shares of seam chain [0-9]+ of the band parts it kept within 3 s" ;;
  peer-shares) expected="rank 1 did (not send its shares of seam chain [0-9]+ of the band parts it kept|not take seam chain [0-9]+) within 3 s" ;;
  write) expected="rank 0 has waited 3 s for the other ranks in one step of writing '[^']*out.h5'" ;;
  idle) expected="rank 1 has not answered" ;;
  *) expected="rank 1 (has not answered|did not take)" ;;
esac
grep -qE "$expected" "$work/log" || fail "no message '$expected'"
[ "$mode" != share ] || ! grep -q "rank 1 has not" "$work/log" || fail "rank 1 blamed for rank 2's silence"
[ "$mode" != share-oom ] || [ "$elapsed" -le 20 ] || fail "took ${elapsed} s (limit 20 s for an error rank 2 reports)"
# 3 s of silence where a user's run waits 60-120 s; the run up to the fault takes 1-16 s (up to
# 16 s beside other tests: scripts/test.sh runs the tests that wait beside the rest).
[[ $mode != silent && $mode != chain && $mode != grow && $mode != take && $mode != links && $mode != *shares && $mode != write ]] || [ "$elapsed" -le 30 ] || fail "took ${elapsed} s (limit 30 s: 3 s of silence)"
if [ "$mode" = write ]; then
  after=$(cd "$work" && ls -A | grep -vx 'torus.off\|log' | xargs sha256sum)
  [ "$after" = "$before" ] || fail "the earlier set did not stay as it was: $(diff <(echo "$before") <(echo "$after"))"
else
  ls "$work"/out.* > /dev/null 2>&1 && fail "output files left: $(ls "$work"/out.*)"
fi
echo "ok ($mode): exit $code after ${elapsed} s: $(grep -m1 -E "$expected" "$work/log")"
