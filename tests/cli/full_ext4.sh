#!/usr/bin/env bash
# A local disk fills up while partet writes to it around the page cache (ext4, O_DIRECT: the
# direct path a tmpfs never takes), and the whole disk is too small for the files: no room can be
# made there, so the run must not wait (--wait-for-space left at its 20 min) but end at once with
# the disk's error and its size, publish nothing, leave no temporary behind, and leave the previous
# mesh at the same prefix byte for byte; in one process and on 2 ranks (rank 1 formats half of the
# lines rank 0 writes). The disk is an ext4
# image on a loop device; without loop mounts (not root, or a container that forbids them) the
# test exits 77 (skipped). Then --scratch on the full disk: a warning, and the same mesh as in memory;
# and --checkpoint on it: a warning, the same mesh, nothing left in the checkpoint. Last, on a
# second disk: one too full for the smallest files of a mesh is refused before the meshing; one
# with room for those but not for this mesh's makes the mesh wait until room is made, then the
# files are written and check; one with room for this mesh's smallest files but not for its files
# fills up during the write: the mesh is kept, waits for room, and is written again, the same
# files as on an empty disk (in one process; on 2 ranks with the XDMF set, whose parallel HDF5
# write is what fails; and on 2 ranks with --check, the mesh assembled on rank 0). disk_space.sh
# has the rest, with the room set by a test hook.
# Usage: full_ext4.sh PARTET MPIEXEC
set -euo pipefail
partet=$1 mpiexec=$2
# Room is looked for every second, not every 10 s: the test makes it at once (5 waits, 45 s less).
export PARTET_TEST_DISK_POLL_S=1
work=$(mktemp -d)
trap 'kill $(jobs -p) 2> /dev/null || true; umount "$work/disk" "$work/room" 2> /dev/null || true; rm -rf "$work"' EXIT
cd "$work"
command -v mkfs.ext4 > /dev/null || { echo "SKIP: no mkfs.ext4 (e2fsprogs)"; exit 77; }
truncate -s 8M disk.img
mkfs.ext4 -q -F disk.img
mkdir disk
mount -o loop disk.img disk 2> /dev/null || { echo "SKIP: loop mounts are not permitted here"; exit 77; }
[ "$(stat -f -c %T disk)" = ext2/ext3 ] || { echo "FAIL: disk is not ext4: $(stat -f -c %T disk)"; exit 1; }

"$partet" generate genus3 --faces 4000 -o small.off > /dev/null
"$partet" generate genus3 --faces 80000 -o big.off > /dev/null
"$partet" mesh small.off -o disk/m --pieces 2 --quiet
(cd disk && md5sum m.* > ../before.md5)

for n in 1 2; do
  started=$SECONDS
  if "$mpiexec" -n $n "$partet" mesh big.off -o disk/m --pieces 4 --verbose > log 2>&1; then
    echo "FAIL: $n rank(s): a full disk exited 0"; exit 1
  fi
  took=$((SECONDS - started))
  grep -q "around the page cache" log || { echo "FAIL: $n rank(s): no file was written directly:"; cat log; exit 1; }
  ! grep -q "waiting up to" log || { echo "FAIL: $n rank(s): waited for room the disk cannot have:"; grep "warning\|error" log; exit 1; }
  grep -q "error: cannot write 'disk/m\.[a-z]*': No space left on device (the files of this mesh take more than the [0-9]* MB the write had, and the disk at $work/disk holds [0-9]* MB in all, so no room can be made there for them: nothing was written; write elsewhere (-o) and run again" log \
    || { echo "FAIL: $n rank(s): not the disk's error and size:"; grep error log; exit 1; }
  [ $took -lt 120 ] || { echo "FAIL: $n rank(s): took $took s"; exit 1; }
  (cd disk && md5sum --quiet -c ../before.md5) || { echo "FAIL: $n rank(s): the previous mesh changed"; exit 1; }
  left=$(cd disk && ls -A | grep -v -x -e lost+found -e 'm\.\(node\|ele\|face\|neigh\)' || true)
  [ -z "$left" ] || { echo "FAIL: $n rank(s): files left: $left"; exit 1; }
  echo "ok: $n rank(s): $(grep -o "cannot write '[^']*': No space left on device" log | head -n 1)," \
    "$(grep -o "holds [0-9]* MB in all" log), no wait ($took s in all), $(grep -c "around the page cache" log) file(s)" \
    "written directly, the previous mesh intact, nothing left"
done

# --scratch on the full disk: the bulks that cannot be written stay in memory, with a warning;
# the run succeeds with the same mesh as without, and leaves nothing on the disk.
mkdir disk/ck  # for --checkpoint below: a directory that exists on the disk once it is full
dd if=/dev/zero of=disk/filler bs=1M > /dev/null 2>&1 || true
dd if=/dev/zero of=disk/filler2 bs=1k > /dev/null 2>&1 || true  # what a whole MB no longer fits in
for n in 1 2; do
  "$mpiexec" -n $n "$partet" mesh small.off -o plain --pieces 4 --quiet || { echo "FAIL: $n rank(s): no mesh"; exit 1; }
  "$mpiexec" -n $n "$partet" mesh small.off -o spilled --pieces 4 --scratch disk > log 2>&1 \
    || { echo "FAIL: $n rank(s): --scratch on a full disk failed:"; cat log; exit 1; }
  grep -q "cannot write the pieces' meshes to a scratch file in 'disk' (No space left on device)" log \
    || { echo "FAIL: $n rank(s): no warning of the full scratch disk:"; cat log; exit 1; }
  for f in node ele face neigh; do
    cmp -s plain.$f spilled.$f || { echo "FAIL: $n rank(s): spilled.$f differs"; exit 1; }
  done
  left=$(cd disk && ls -A | grep -v -x -e lost+found -e filler -e filler2 -e ck -e 'm\.\(node\|ele\|face\|neigh\)' || true)
  [ -z "$left" ] || { echo "FAIL: $n rank(s): files left on the scratch disk: $left"; exit 1; }
  echo "ok: $n rank(s): --scratch on a full disk: a warning, the same mesh as in memory, nothing left"
done

# --checkpoint on the full disk: the pieces that cannot be kept cost one warning per rank; the
# run succeeds with the same mesh, and no piece file or temporary is left in the checkpoint.
for n in 1 2; do
  "$mpiexec" -n $n "$partet" mesh small.off -o kept --pieces 4 --checkpoint disk/ck > log 2>&1 \
    || { echo "FAIL: $n rank(s): --checkpoint on a full disk failed:"; cat log; exit 1; }
  grep -q "cannot keep meshed pieces in the checkpoint ('disk/ck/piece-[0-9]*-[0-9a-f]*\.bin[^']*': No space left on device)" log \
    || { echo "FAIL: $n rank(s): no warning of the full checkpoint disk:"; cat log; exit 1; }
  [ "$(grep -c "cannot keep meshed pieces" log)" -le $n ] || { echo "FAIL: $n rank(s): more than one warning per rank:"; cat log; exit 1; }
  for f in node ele face neigh; do
    cmp -s plain.$f kept.$f || { echo "FAIL: $n rank(s): kept.$f differs"; exit 1; }
  done
  left=$(ls -A disk/ck)
  [ -z "$left" ] || { echo "FAIL: $n rank(s): files left in the checkpoint: $left"; exit 1; }
  echo "ok: $n rank(s): --checkpoint on a full disk: $(grep -c "cannot keep meshed pieces" log) warning(s), the same mesh, nothing left"
done

# Room for the files: a fresh disk, filled by a neighbour up to ROOM MB of free space.
truncate -s 64M room.img
mkfs.ext4 -q -F room.img
mkdir room
mount -o loop room.img room
free_mb() { stat -f -c '%f %S' room | awk '{printf "%d", $1 * $2 / 1048576}'; }  # root may use every free block
leave_free() { rm -f room/neighbour; fallocate -l $(( ($(free_mb) - $1) * 1048576 )) room/neighbour; }
at_least() { sed -n 's/.*take at least \([0-9]*\) MB.*/\1/p' log | head -n 1; }
leave_free 1
if "$partet" mesh big.off -o room/m --pieces 4 --verbose > log 2>&1; then echo "FAIL: a disk without room exited 0"; exit 1; fi
code=$?
grep -q "no room for the output: .*, and $work/room has [01] MB free: make room there, or write elsewhere (-o)\. Nothing was meshed\." log \
  && ! grep -q "pieces 1/" log && [ -z "$(ls room | grep -v -x -e lost+found -e neighbour)" ] \
  || { echo "FAIL: a disk without room (exit $code):"; cat log; exit 1; }
least_input=$(at_least)
echo "ok: 1 rank: a disk with 1 MB free refused before the meshing: the input's mesh takes at least $least_input MB"
# This mesh's own least room (its counts known once meshed), then a disk with room between the two.
PARTET_TEST_FREE_DISK_MB=1e9,0 "$partet" mesh big.off -o mine --pieces 4 --wait-for-space 0 > log 2>&1 || true
least_mesh=$(at_least)
[ -n "$least_input" ] && [ -n "$least_mesh" ] && [ "$least_mesh" -ge $((least_input + 2)) ] \
  || { echo "FAIL: no room between the input's least files ($least_input MB) and the mesh's ($least_mesh MB)"; cat log; exit 1; }
for n in 1 2; do
  leave_free $(( (least_input + least_mesh) / 2 ))
  "$mpiexec" -n $n "$partet" mesh big.off -o room/m --pieces 4 --check > log 2>&1 &
  pid=$!
  for _ in $(seq 1200); do grep -q "for room (--wait-for-space)" log && break; kill -0 $pid 2> /dev/null || break; sleep 0.1; done
  grep -q "warning: $work/room has [0-9]* MB free, and the files of this mesh ([0-9]* points, [0-9]* tets) take at least $least_mesh MB as tetgen: waiting up to 20 min for room" log \
    || { echo "FAIL: $n rank(s): no wait for room:"; cat log; exit 1; }
  rm room/neighbour  # room is made
  wait $pid || { echo "FAIL: $n rank(s): no mesh once room was made:"; cat log; exit 1; }
  grep -q "room at $work/room after [0-9]* s: writing" log && grep -q "check passed" log \
    || { echo "FAIL: $n rank(s): not written and checked:"; cat log; exit 1; }
  echo "ok: $n rank(s): a disk filled during the meshing: the mesh waited $(grep -o 'after [0-9]* s' log | cut -c7-) for room, then was written and checked"
  rm room/m.*
done

# A disk that fills up during the write: room for this mesh's smallest files, not for its files.
# In one process the TetGen files fail; on 2 ranks the TetGen files fit and then the XDMF set's
# HDF5 file, written by both ranks at once, fails (the mesh left on the ranks), or, with --check
# (rank 0 assembles the mesh and the ranks format its rows), the .vtu file. Once room is made the
# same files are written.
mkdir plain
"$partet" mesh big.off -o plain/m --pieces 4 --format tetgen,xdmf,vtu --quiet
files_of() {  # FORMATS: the names of their files
  echo m.node m.ele m.face m.neigh
  case $1 in *xdmf*) echo m.xdmf m_boundary.xdmf m.h5 m_boundary.h5 ;; esac
  case $1 in *vtu*) echo m.vtu ;; esac
}
files_mb() { (cd plain && du -b -c $(files_of "$1")) | awk 'END {printf "%d", $1 / 1048576}'; }
tetgen_mb=$(files_mb tetgen)
for run in "1 tetgen" "2 tetgen,xdmf" "2 tetgen,vtu --check"; do
  set -- $run
  n=$1 formats=$2 options=("${@:3}")
  all_mb=$(files_mb $formats)
  # Between this mesh's least room and its TetGen files; on 2 ranks, room for the TetGen files only.
  room_mb=$(( n == 1 ? (least_mesh + tetgen_mb) / 2 : tetgen_mb + (all_mb - tetgen_mb) / 2 ))
  [ "$room_mb" -gt "$least_mesh" ] && [ "$room_mb" -lt "$all_mb" ] \
    || { echo "FAIL: no room between the least room ($least_mesh MB) and the files ($all_mb MB)"; exit 1; }
  what="$n rank(s), $formats${options[*]:+ ${options[*]}}"
  leave_free "$room_mb"
  "$mpiexec" -n $n "$partet" mesh big.off -o room/m --pieces 4 --format $formats "${options[@]}" > log 2>&1 &
  pid=$!
  for _ in $(seq 1200); do grep -q "ran out while the files were written" log && break; kill -0 $pid 2> /dev/null || break; sleep 0.1; done
  grep -q "warning: the disk ran out while the files were written (cannot write 'room/m\.[a-z0-9]*': .*No space left on device); the mesh is kept: waiting up to 20 min for more room at $work/room than the [0-9]* MB the write had (--wait-for-space); make room there, and the files are written" log \
    || { echo "FAIL: $what: no wait after the disk filled up during the write:"; cat log; exit 1; }
  left=$(ls room | grep -v -x -e lost+found -e neighbour || true)
  [ -z "$left" ] || { echo "FAIL: $what: the failed write left $left"; exit 1; }
  rm room/neighbour  # room is made
  wait $pid || { echo "FAIL: $what: no mesh once room was made:"; cat log; exit 1; }
  grep -q "warning: more room at $work/room after [0-9]* s: writing again" log && grep -q "^partet: stages: .* room_wait [1-9][0-9]*\.[0-9]*[ ;]" log \
    || { echo "FAIL: $what: not written again (or no room_wait):"; cat log; exit 1; }
  for f in $(files_of $formats); do
    cmp -s plain/$f room/$f || { echo "FAIL: $what: room/$f differs from the mesh written on an empty disk"; exit 1; }
  done
  "$partet" check big.off room/m > check.log 2>&1 || { echo "FAIL: $what: the files written again do not check:"; cat check.log; exit 1; }
  echo "ok: $what: the disk filled up during the write ($(grep -o "cannot write 'room/[^']*'" log | head -n 1); $room_mb MB free," \
    "$all_mb MB of files): the mesh waited $(grep -o 'after [0-9]* s: writing again' log | cut -d' ' -f2) s, then the same files were written again, and check"
  rm room/m*
done
