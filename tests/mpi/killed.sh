#!/usr/bin/env bash
# A run killed outright leaves no temporary behind: the reaper (src/runner/reaper.hpp) removes
# what the killed process can no longer remove. (1) SIGKILL to a one-process run while it writes
# its files; (2) SIGKILL to rank 0 under the launcher while it writes; (3) SIGTERM to mpirun while
# the ranks write: Open MPI's mpirun sends SIGKILL a millisecond or two after SIGTERM, which a
# loaded rank's own cleanup loses. Each time the previous set at the prefix is
# kept byte for byte, and no process of the run is left.
# Usage: killed.sh PARTET MPIEXEC
set -uo pipefail
partet=$(realpath "$1")
mpiexec=$2
source "$(dirname "$0")/../harness.sh"
cd "$work"
"$partet" generate torus --faces 200000 -o "$work/in.off" > /dev/null || exit 1
"$partet" mesh in.off -o m --pieces 4 --quiet --format tetgen,pvtu || exit 1
mkdir before && cp m.* m_*.vtu before/

# Starts the run (the command given), waits until it is inside a large file's write (a temporary
# with its first 4 MB, each 4 MB then taking 3 s); false if none comes within 120 s.
writing_large() { [ -n "$(find . -maxdepth 1 -name '*.tmp-*' -size +4095k)" ]; }
start_writing() {
  PARTET_TEST_WRITE_DELAY_MS=3000 "$@" > log 2>&1 &
  pid=$!
  wait_while_running 120 writing_large
}
# Checks what a killed run left: NAME.
after_kill() {
  local changed="" left
  wait_gone 30 "mesh $work/in.off" || bad "$1: processes left: $(pgrep -af "mesh $work/in.off")"
  left=$(ls | grep '\.tmp-')
  for f in before/*; do cmp -s "$f" "$(basename "$f")" || changed+=" $(basename "$f")"; done
  if [ -z "$left" ] && [ -z "$changed" ]; then ok "$1: no temporary left, the previous set kept"
  else
    bad "$1: left '$left', changed '$changed': $(tail -n 3 log)"
    rm -f ./*.tmp-* && cp before/* .  # the next step starts as this one did
  fi
}
mesh=(mesh "$work/in.off" -o m --pieces 4 --format tetgen,pvtu)

# 1. SIGKILL to a one-process run while it writes.
if start_writing "$partet" "${mesh[@]}"; then
  kill -KILL "$pid"
  wait "$pid" 2> /dev/null
  after_kill "SIGKILL while writing (one process)"
else bad "one process: no temporary seen: $(cat log)"; fi

# 2. SIGKILL to rank 0 under the launcher while it writes.
if start_writing "$mpiexec" -n 2 -x PARTET_TEST_WRITE_DELAY_MS "$partet" "${mesh[@]}"; then
  for p in $(pgrep -f "mesh $work/in.off"); do
    tr '\0' '\n' < "/proc/$p/environ" 2> /dev/null | grep -qx OMPI_COMM_WORLD_RANK=0 || continue
    [ "$(awk '{print $4}' "/proc/$p/stat")" = "$pid" ] && kill -KILL "$p"  # the rank, not its reaper
  done
  wait "$pid"
  code=$?
  [ $code != 0 ] || bad "SIGKILL to rank 0: the job exited 0"
  after_kill "SIGKILL to rank 0 while it writes (2 ranks)"
else bad "2 ranks: no temporary seen: $(cat log)"; fi

# 3. SIGTERM to mpirun while the ranks write, rank 0's own cleanup slowed as on a loaded machine:
# once rank 1 has ended, mpirun kills rank 0 at once (SIGKILL), and the reaper cleans up.
if start_writing "$mpiexec" -n 2 -x PARTET_TEST_WRITE_DELAY_MS -x PARTET_TEST_INTERRUPT_DELAY=0:5000 \
  "$partet" "${mesh[@]}"; then
  kill -TERM "$pid"
  wait "$pid"
  grep -q interrupted log && bad "SIGTERM to mpirun: rank 0 cleaned up itself (no test of the reaper)"
  after_kill "SIGTERM to mpirun while writing, a rank's own cleanup too late"
else bad "SIGTERM to mpirun: no temporary seen: $(cat log)"; fi

summary
