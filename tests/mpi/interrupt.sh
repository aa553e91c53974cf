#!/usr/bin/env bash
# No orphaned processes and a clear message: (1) SIGTERM to a one-rank run ends it at once with
# exit code 143 and "interrupted", its TetGen child dies with it, and no file (temporary or
# final) is left; (2) SIGKILL of a rank under the launcher takes its TetGen child with it and
# ends the job without output; (3) SIGTERM to a 2-rank job in the middle of a large file's
# write keeps the previous set and leaves no temporary; (4) so does SIGTERM while rank 1 writes
# an MSH partition file; (5) and while rank 1 writes the .vtu files of the pieces it keeps (the
# mesh never assembled).
# Usage: interrupt.sh PARTET MPIEXEC
set -uo pipefail
partet=$1 mpiexec=$2
source "$(dirname "$0")/../harness.sh"
"$partet" generate torus --faces 200000 -o "$work/big.off" > /dev/null || exit 1
"$partet" generate genus3 --faces 6000 -o "$work/small.off" > /dev/null || exit 1  # previous sets
processes() {  # running ones (a zombie waiting to be reaped does not count)
  local n=0
  for pid in $(pgrep -f "mesh $work/big.off"); do
    [ "$(awk '{print $3}' "/proc/$pid/stat" 2> /dev/null)" = Z ] || n=$((n + 1))
  done
  echo "$n"
}
# Waits until a TetGen child (a partet whose parent is partet) runs; prints its pid.
child_of_job() {
  for i in $(seq 600); do
    for pid in $(pgrep -f "mesh $work/big.off"); do
      parent=$(awk '{print $4}' "/proc/$pid/stat" 2> /dev/null)
      [ -n "$parent" ] && [ "$(cat "/proc/$parent/comm" 2> /dev/null)" = partet ] && { echo "$pid"; return; }
    done
    sleep 0.05
  done
}

# 1. SIGTERM to a one-rank run.
"$partet" mesh "$work/big.off" -o "$work/one" --pieces 2 > "$work/log1" 2>&1 &
rank=$!
child=$(child_of_job)
[ -n "$child" ] || bad "no TetGen child seen"
kill -TERM "$rank"
wait "$rank"
code=$?
sleep 1
[ "$code" -eq 143 ] && ok "SIGTERM: exit code 143" || bad "SIGTERM: exit code $code"
grep -q "interrupted" "$work/log1" && ok "SIGTERM: says $(grep -m1 interrupted "$work/log1")" || bad "SIGTERM: no message"
[ "$(processes)" -eq 0 ] && ok "SIGTERM: no process left" || bad "SIGTERM: $(processes) processes left"
ls "$work" | grep -q '^one' && bad "SIGTERM: files left: $(ls "$work")" || ok "SIGTERM: no file left"

# 2. SIGKILL of rank 1 under the launcher, while its TetGen child runs.
"$mpiexec" -n 2 "$partet" mesh "$work/big.off" -o "$work/two" --pieces 4 > "$work/log2" 2>&1 &
launcher=$!
# Rank 1 and its child are taken in one look: a second look could fall between two pieces.
victim="" victim_child=""
for i in $(seq 600); do
  for pid in $(pgrep -f "mesh $work/big.off"); do
    if tr '\0' '\n' < "/proc/$pid/environ" 2> /dev/null | grep -qx "OMPI_COMM_WORLD_RANK=1"; then
      child=$(pgrep -P "$pid" | head -1)
      [ -n "$child" ] && victim=$pid victim_child=$child
    fi
  done
  [ -n "$victim" ] && break
  sleep 0.05
done
[ -n "$victim" ] || bad "rank 1 with a TetGen child not found"
kill -KILL "$victim"
# Gone, or a zombie waiting to be reaped: either way it no longer runs.
alive() { [ -e "/proc/$1/stat" ] && [ "$(awk '{print $3}' "/proc/$1/stat" 2> /dev/null)" != Z ]; }
# The rank dies once all its threads can stop (on a loaded host a thread in uninterruptible I/O
# makes that later; CI saw its child still running 1 s after the signal); its child must die
# within 1 s of the rank's death.
for i in $(seq 200); do alive "$victim" || break; sleep 0.05; done
alive "$victim" && bad "SIGKILL: rank 1 still runs 10 s after SIGKILL"
sleep 1
[ -n "$victim_child" ] && ! alive "$victim_child" && ok "SIGKILL: the rank's TetGen child died with it" ||
  bad "SIGKILL: the TetGen child $victim_child still runs 1 s after rank 1 died"
timeout 30 tail --pid="$launcher" -f /dev/null
wait "$launcher"
code=$?
[ "$code" -ne 0 ] && ok "SIGKILL: the job ended with exit code $code" || bad "SIGKILL: exit code 0"
sleep 1
[ "$(processes)" -eq 0 ] && ok "SIGKILL: no process left" || bad "SIGKILL: $(processes) processes left"
ls "$work" | grep -q '^two\.[a-z]*$' && bad "SIGKILL: output files: $(ls "$work")" || ok "SIGKILL: no output file"

# 3. SIGTERM to a 2-rank job in the middle of its write: a file of the TetGen set is being written
# in 4 MB buffers (around the page cache where the filesystem allows), slowed by
# PARTET_TEST_WRITE_DELAY_MS so the signal lands inside it, while rank 1 sends rank 0 the lines
# of the bulks it keeps (the mesh is not assembled) or waits to write its .pvtu piece files. The job ends with "interrupted", the previous set at the prefix is kept byte for
# byte, and no temporary is left.
"$partet" mesh "$work/small.off" -o "$work/w" --pieces 4 --quiet --format tetgen,pvtu
mkdir "$work/before" && cp "$work"/w.* "$work"/w_*.vtu "$work/before/"
PARTET_TEST_WRITE_DELAY_MS=3000 "$mpiexec" -n 2 -x PARTET_TEST_WRITE_DELAY_MS "$partet" mesh "$work/big.off" \
  -o "$work/w" --pieces 4 --format tetgen,pvtu > "$work/log3" 2>&1 &
launcher=$!
large=""
for i in $(seq 1200); do  # up to 60 s for the meshing
  large=$(find "$work" -maxdepth 1 -name 'w.*.tmp-*' -size +4095k | head -n 1)
  [ -n "$large" ] && break
  sleep 0.05
done
[ -n "$large" ] && ok "write: interrupted with $(basename "$large" | cut -d. -f1-2)'s first 4 MB written" ||
  bad "write: no temporary of 4 MB seen"
# After SIGTERM to the launcher: "interrupted", the previous set (a copy in BEFORE) kept byte for
# byte, no temporary and no process left.
after_interrupt() {  # NAME LOG BEFORE
  kill -TERM "$launcher"
  timeout 30 tail --pid="$launcher" -f /dev/null
  wait "$launcher"
  local code=$? changed=""
  sleep 1
  [ "$code" -ne 0 ] && ok "$1: exit code $code" || bad "$1: exit code 0"
  grep -q "interrupted" "$2" && ok "$1: says $(grep -m1 interrupted "$2")" || bad "$1: no message"
  for f in "$3"/*; do cmp -s "$f" "$work/$(basename "$f")" || changed+=" $(basename "$f")"; done
  [ -z "$changed" ] && ok "$1: the previous set ($(ls "$3" | wc -l) files) kept" || bad "$1: changed:$changed"
  ls "$work" | grep -q '\.tmp-' && bad "$1: temporaries left: $(ls "$work" | grep '\.tmp-')" || ok "$1: no temporary left"
  [ "$(processes)" -eq 0 ] && ok "$1: no process left" || bad "$1: $(processes) processes left"
}
after_interrupt write "$work/log3" "$work/before"

# rank1_holds PATTERN MIN_BYTES: waits (up to 60 s) until rank 1 of the job meshing big.off holds
# open a file matching PATTERN with at least MIN_BYTES, and prints its path ("" if never).
rank1_holds() {
  local pid fd target
  for i in $(seq 1200); do
    for pid in $(pgrep -f "mesh $work/big.off"); do
      tr '\0' '\n' < "/proc/$pid/environ" 2> /dev/null | grep -qx OMPI_COMM_WORLD_RANK=1 || continue
      for fd in /proc/"$pid"/fd/*; do
        target=$(readlink "$fd" 2> /dev/null) || continue
        # shellcheck disable=SC2053 # PATTERN is a glob
        [[ "$target" == $1 ]] && [ "$(stat -c %s "$target" 2> /dev/null || echo 0)" -ge "$2" ] &&
          { echo "$target"; return; }
      done
    done
    sleep 0.05
  done
}

# 4. SIGTERM while rank 1 writes an MSH partition file: the ranks write the partitions at once,
# each slowed as above; the signal comes once a temporary rank 1 holds open has its first buffer (a
# little under 4 MiB).
rm -f "$work"/w.* "$work"/w_*.vtu
"$partet" mesh "$work/small.off" -o "$work/p" --pieces 2 --quiet --format msh-parts
mkdir "$work/before4" && cp "$work"/p_*.msh "$work/before4/"
# (Four pieces: their partitions have over 4 MB each, and a torus cut in two meshes 4 times slower.)
PARTET_TEST_WRITE_DELAY_MS=3000 "$mpiexec" -n 2 -x PARTET_TEST_WRITE_DELAY_MS "$partet" mesh "$work/big.off" \
  -o "$work/p" --pieces 4 --format msh-parts > "$work/log4" 2>&1 &
launcher=$!
held=$(rank1_holds "$work/p_*.msh.tmp-*" 4000000)
[ -n "$held" ] && ok "partition write: interrupted while rank 1 writes $(basename "$held" | cut -d. -f1-2)" ||
  bad "partition write: rank 1 was not seen writing a partition"
after_interrupt "partition write" "$work/log4" "$work/before4"

# 5. SIGTERM while rank 1 writes a .pvtu piece file of a mesh it was never assembled into: rank 1
# writes the files of the bulks it keeps (spread_piece_files); the signal comes once it holds one
# open, slowed as above (its files are over 4 MB: a larger input, a sphere, which meshes 10 times
# faster than a torus of as many faces; two pieces). The previous set comes from a small input.
rm -f "$work"/p_*.msh
"$partet" generate sphere --faces 420000 -o "$work/big.off" > /dev/null || exit 1
"$mpiexec" -n 2 "$partet" mesh "$work/small.off" -o "$work/v" --pieces 2 --quiet --format pvtu --report "$work/v.json"
grep -q '"assembled_on_rank0": false' "$work/v.json" || bad "spread write: the mesh was assembled"
mkdir "$work/before5" && cp "$work"/v.pvtu "$work"/v_*.vtu "$work/before5/"
rm "$work/v.json"
PARTET_TEST_WRITE_DELAY_MS=3000 "$mpiexec" -n 2 -x PARTET_TEST_WRITE_DELAY_MS "$partet" mesh "$work/big.off" \
  -o "$work/v" --pieces 2 --format pvtu > "$work/log5" 2>&1 &
launcher=$!
held=$(rank1_holds "$work/v_*.vtu.tmp-*" 0)
[ -n "$held" ] && ok "spread write: interrupted while rank 1 writes its $(basename "$held" | cut -d. -f1-2)" ||
  bad "spread write: rank 1 was not seen writing a piece file"
after_interrupt "spread write" "$work/log5" "$work/before5"

summary
