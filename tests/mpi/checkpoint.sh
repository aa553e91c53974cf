#!/usr/bin/env bash
# --checkpoint DIR: a run stopped part way (SIGTERM, as a batch system's time limit or preemption
# sends it) loses none of the pieces it had meshed, and a rerun with the same DIR gives the same
# files as a run never stopped, taking those pieces from DIR instead of meshing them again.
#   1. stopped: piece 4's process is stalled (PARTET_INJECT_FAILURE=4:stall) so the others finish
#      first; SIGTERM to mpiexec once DIR holds 5 pieces; no output is published;
#   2. rerun on RANKS ranks: the reference run's files byte for byte, 5 pieces taken from DIR
#      (only piece 4 meshed), and DIR then holds all 6;
#   2b. the same after SIGKILL to every process of the run;
#   3. a kept piece cut short (a damaged file) is skipped with a warning and meshed again: same
#      files; the file is whole again afterwards;
#   4. in one process (another rank count): every piece taken, same files;
#   5. other options (a quality bound): no piece taken (what TetGen is given differs);
#   6. a DIR that cannot be made is refused before any work;
#   7. two runs at once sharing a new DIR: both write the reference files, DIR ends with the 6
#      pieces and no temporary.
# Usage: checkpoint.sh PARTET MPIEXEC RANKS
set -uo pipefail
partet=$1 mpiexec=$2 ranks=$3
source "$(dirname "$0")/../harness.sh"
cd "$work"
"$partet" generate genus3 --faces 20000 -o g.off > /dev/null || exit 1
on_ranks=("$mpiexec" -n "$ranks" --oversubscribe)
mesh_args=(mesh g.off --pieces 6)
same_as_ref() {  # RUN: its TetGen files are the reference run's byte for byte
  local ext
  for ext in node ele face neigh; do cmp -s "ref.$ext" "$1.$ext" || return 1; done
}
taken() { grep -c "taken from the checkpoint" "$1"; }

"${on_ranks[@]}" "$partet" "${mesh_args[@]}" -o ref --quiet || { bad "the reference run failed"; summary; exit 1; }

# 1. Stopped part way.
PARTET_INJECT_FAILURE=4:stall PARTET_TEST_STALL_S=120 "${on_ranks[@]}" -x PARTET_INJECT_FAILURE -x PARTET_TEST_STALL_S \
  "$partet" "${mesh_args[@]}" -o stopped --checkpoint ck > stopped.log 2>&1 &
pid=$!
kept() { [ "$(ls ck 2> /dev/null | grep -c '^piece-.*\.bin$')" -ge 5 ]; }
if wait_while_running 120 kept; then
  sleep 0.5
  kill -TERM "$pid"
  wait "$pid"
  code=$?
  if [ "$code" -ne 0 ] && [ ! -e stopped.node ] &&
    grep -q "no output written; .*the pieces meshed so far are kept in ck: the same command takes them" stopped.log; then
    ok "stopped by SIGTERM with 5 pieces kept: exit $code, nothing published, the kept pieces said"
  else bad "stopped by SIGTERM: exit $code, $(ls stopped.* 2> /dev/null | tr '\n' ' '), said: $(tail -n 2 stopped.log)"; fi
else
  kill -KILL "$pid" 2> /dev/null
  bad "the stalled run did not keep 5 pieces: $(ls ck 2> /dev/null | tr '\n' ' '); it said: $(tail -n 3 stopped.log)"
fi

# 2. The rerun.
"${on_ranks[@]}" "$partet" "${mesh_args[@]}" -o rerun --checkpoint ck --report rerun.json > rerun.log 2>&1 ||
  bad "the rerun failed: $(cat rerun.log)"
counted=$(python3 -c 'import json,sys; print(int(sum(r["pieces_from_checkpoint"] for r in json.load(open(sys.argv[1]))["rank"])))' rerun.json)
if same_as_ref rerun && [ "$(taken rerun.log)" = 5 ] && ! grep -q "piece 4 taken" rerun.log &&
  [ "$(ls ck | grep -c '^piece-.*\.bin$')" = 6 ] && [ "$counted" = 5 ] &&
  grep -q "checkpoint: 5 pieces taken from ck" rerun.log; then
  ok "rerun on $ranks ranks: the reference files byte for byte, 5 pieces taken from the checkpoint (said and reported), piece 4 meshed"
else
  bad "rerun: same files: $(same_as_ref rerun && echo yes || echo no), pieces taken: $(taken rerun.log), reported: $counted, kept: $(ls ck | tr '\n' ' ')"
fi

# 2b. The same with SIGKILL to every process of the run (as a node that dies, or the OOM killer):
#     nothing can clean up, and still every piece kept is taken.
PARTET_INJECT_FAILURE=4:stall PARTET_TEST_STALL_S=120 "${on_ranks[@]}" -x PARTET_INJECT_FAILURE -x PARTET_TEST_STALL_S \
  "$partet" "${mesh_args[@]}" -o killed --checkpoint "$work/ck_killed" > killed.log 2>&1 &
pid=$!
kept_killed() { [ "$(ls ck_killed 2> /dev/null | grep -c '^piece-.*\.bin$')" -ge 5 ]; }
if wait_while_running 120 kept_killed; then
  pkill -KILL -f "$work/ck_killed"
  { wait "$pid"; } 2> /dev/null
  "${on_ranks[@]}" "$partet" "${mesh_args[@]}" -o after_kill --checkpoint "$work/ck_killed" > after_kill.log 2>&1 ||
    bad "the rerun after SIGKILL failed: $(cat after_kill.log)"
  if same_as_ref after_kill && [ "$(taken after_kill.log)" = 5 ]; then
    ok "every process killed (SIGKILL) with 5 pieces kept: the rerun takes them, the reference files"
  else
    bad "after SIGKILL: same files: $(same_as_ref after_kill && echo yes || echo no), taken: $(taken after_kill.log)"
  fi
else
  pkill -KILL -f "$work/ck_killed"
  bad "the run to be killed did not keep 5 pieces: $(ls ck_killed 2> /dev/null | tr '\n' ' ')"
fi

# 3. A damaged file.
damaged=$(ls ck/piece-2-*.bin)
truncate -s -100 "$damaged"
"${on_ranks[@]}" "$partet" "${mesh_args[@]}" -o damaged --checkpoint ck > damaged.log 2>&1 || bad "the run with a damaged file failed"
if same_as_ref damaged && [ "$(taken damaged.log)" = 5 ] && grep -q "is incomplete or damaged: meshing piece 2 again" damaged.log; then
  ok "a damaged kept piece: skipped with a warning, meshed again, the reference files"
else
  bad "damaged: same files: $(same_as_ref damaged && echo yes || echo no), taken: $(taken damaged.log), said: $(grep -i warning damaged.log)"
fi

# 4. One process, every piece taken.
"$partet" "${mesh_args[@]}" -o one --checkpoint ck > one.log 2>&1 || bad "the run in one process failed"
if same_as_ref one && [ "$(taken one.log)" = 6 ] && ! grep -qi warning one.log; then
  ok "in one process: all 6 pieces taken (the damaged one was kept again whole), the reference files"
else
  bad "one process: same files: $(same_as_ref one && echo yes || echo no), taken: $(taken one.log)"
fi

# 5. Other options.
"${on_ranks[@]}" "$partet" "${mesh_args[@]}" -o quality --quality 2 --checkpoint ck > quality.log 2>&1 || bad "the run with --quality failed"
[ "$(taken quality.log)" = 0 ] && ok "with a quality bound no piece is taken" || bad "with --quality $(taken quality.log) pieces were taken"

# 6. A directory that cannot be made.
"$partet" "${mesh_args[@]}" -o none --checkpoint missing/ck > none.log 2>&1
code=$?
[ "$code" = 2 ] && grep -q "checkpoint: cannot make 'missing/ck'" none.log && ok "a checkpoint directory that cannot be made: exit 2, said" ||
  bad "missing parent: exit $code, said: $(cat none.log)"

# 7. Two runs at once, one DIR.
"${on_ranks[@]}" "$partet" "${mesh_args[@]}" -o twin_a --checkpoint shared > twin_a.log 2>&1 &
twin=$!
"${on_ranks[@]}" "$partet" "${mesh_args[@]}" -o twin_b --checkpoint shared > twin_b.log 2>&1
code_b=$?
wait "$twin"
code_a=$?
if [ "$code_a$code_b" = 00 ] && same_as_ref twin_a && same_as_ref twin_b && ! grep -qi warning twin_a.log twin_b.log &&
  [ "$(ls shared | grep -c '^piece-.*\.bin$')" = 6 ] && ! ls shared | grep -q '\.tmp-'; then
  ok "two runs at once sharing one checkpoint: both the reference files, 6 pieces kept, no temporary left"
else
  bad "two runs at once: exit $code_a/$code_b, same files: $(same_as_ref twin_a && same_as_ref twin_b && echo yes || echo no), DIR: $(ls shared | tr '\n' ' ')"
fi
summary
