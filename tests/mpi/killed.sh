#!/usr/bin/env bash
# A run killed outright leaves no temporary behind: the reaper (src/runner/reaper.hpp) removes
# what the killed process can no longer remove. (1) SIGKILL to a one-process run while it writes
# its files; (2) SIGKILL to rank 0 under the launcher while it writes; (3) SIGTERM to mpirun while
# the ranks write: Open MPI's mpirun sends SIGKILL a millisecond or two after SIGTERM, which a
# loaded rank's own cleanup loses. Each time the previous set at the prefix is
# kept byte for byte, and no process of the run is left. (4) The reaper itself killed, then the
# run: its temporaries stay, and the next run on the prefix removes them.
# Usage: killed.sh PARTET MPIEXEC
set -uo pipefail
partet=$(realpath "$1")
mpiexec=$2
source "$(dirname "$0")/../harness.sh"
cd "$work"
"$partet" generate torus --faces 200000 -o "$work/in.off" > /dev/null || exit 1
# The previous set, and the run of step 4 (which needs no large file), from a small input.
"$partet" generate genus3 --faces 6000 -o "$work/small.off" > /dev/null || exit 1
"$partet" mesh small.off -o m --pieces 4 --quiet --format tetgen,pvtu || exit 1
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

# 4. The reaper killed first (SIGKILL), then the one-process run once every temporary is written
# (TetGen files, a .pvtu set's piece files, MSH partitions), as when a node goes down: nothing
# removes them then, but the previous set is kept, and the next run on the prefix removes them all
# (their owner is gone), piece files and partitions included, and publishes its own set.
reaper_of() {  # PID: the reaper that process started (the one holding the other end of its pipe)
  local mine r
  mine=$(for f in /proc/"$1"/fd/*; do readlink "$f"; done 2> /dev/null | grep '^pipe:' | sort -u)
  [ -n "$mine" ] || return
  for r in $(pgrep -x partet-reaper); do
    for f in /proc/"$r"/fd/*; do readlink "$f"; done 2> /dev/null | grep -qxF "$mine" && { echo "$r"; return; }
  done
}
every_temporary() { [ "$(ls | grep -c '\.tmp-')" -ge 13 ]; }  # 4 + 1 + 4 pieces and 4 partitions at least
all=(mesh "$work/small.off" -o m --pieces 4 --format tetgen,pvtu,msh-parts)
PARTET_TEST_PAUSE_BEFORE_PUBLISH_MS=20000 "$partet" "${all[@]}" > log 2>&1 &
pid=$!
if wait_while_running 120 every_temporary; then
  sleep 1  # the last one's bytes
  reaper=$(reaper_of "$pid")
  [ -n "$reaper" ] && kill -KILL "$reaper"
  kill -KILL "$pid"
  wait "$pid" 2> /dev/null
  left=$(ls | grep '\.tmp-' | sed 's/\.tmp-.*//' | tr '\n' ' ')
  changed=""
  for f in before/*; do cmp -s "$f" "$(basename "$f")" || changed+=" $(basename "$f")"; done
  "$partet" "${all[@]}" --quiet > log 2>&1
  code=$?
  remaining=$(ls | grep '\.tmp-')
  if [ -n "$reaper" ] && [[ "$left" == *m_p0.vtu* ]] && [[ "$left" == *m_1.msh* ]] && [ -z "$changed" ] && [ $code = 0 ] &&
    [ -z "$remaining" ] && "$partet" check small.off m > /dev/null 2>&1; then
    ok "reaper and run killed: the temporaries of $left stayed, the previous set kept; the next run removed them and published"
  else
    bad "reaper ('$reaper') and run killed: left '$left', changed '$changed'; the next run: exit $code, left '$remaining': $(tail -n 3 log)"
  fi
else bad "killed reaper: not every temporary seen: $(ls) $(cat log)"; fi

summary
