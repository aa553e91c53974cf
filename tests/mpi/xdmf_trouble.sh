#!/usr/bin/env bash
# The XDMF set's HDF5 files are written by every rank at once, and every rank formats a block of
# the TetGen files' lines; a rank that cannot take part must fail the whole run on every rank,
# publish nothing and leave the previous set as it was:
#   lost:       rank 1 loses its block (fault injection);
#   lost-rows:  the same, writing TetGen files from the assembled mesh (PARTET_TEST_ASSEMBLE);
#   lost-neigh: the same, TetGen files alone, streamed from the ranks keeping the mesh's parts:
#               rank 1 loses the faces its bulk shares with the rest of the mesh;
#   lost-points-FORMAT: the same, TetGen's files or one .vtu file streamed from the ranks keeping
#               the mesh's parts: rank 1 loses the share of the input's points rank 0 gave it
#               to format (so rank 1 must have been given one);
#   full:       the output directory fills up while rank 0 writes the lines the ranks formatted:
#               the run ends with the disk's error, nothing left behind, no rank left waiting;
#   full-hdf5:  the same while both ranks write the XDMF set's HDF5 file;
#   lost-vtu:   the same, writing the piece files of a .pvtu set;
#   lost-msh-parts: the same, writing MSH partitions from the ranks keeping the mesh's parts;
#   oom-FORMAT: rank 1 runs out of memory making its part of a file written from the ranks
#               keeping the mesh's parts (its rows of TetGen's files, a .vtu, .mesh or .msh file
#               streamed to rank 0; its .pvtu piece files or MSH partitions): the run fails with
#               rank 1's own out-of-memory message;
#   not-shared: rank 1 runs in its own mount namespace where the output directory is an empty
#               tmpfs of the same path (a node-local directory, not the one rank 0 writes to);
#               writing its rows into a file of its own there would leave rank 0's file
#               silently incomplete. Needs unshare -m (root); exits 77 (skipped) without it.
#               A .pvtu set works there: rank 0 writes the piece files rank 1 cannot see (rank 1
#               sends the files of the bulks it keeps);
#   full-pvtu:  the disk fills while both ranks write their piece files of a .pvtu set;
#   full-msh:   the disk fills while rank 0 writes one MSH file, its rows streamed from the ranks
#               keeping the mesh's parts;
#   full-vtu:   the same with one .vtu file (its arrays compressed as they come, their offsets
#               written last);
#   full-msh-parts: the disk fills while both ranks write their MSH partitions.
# Usage: xdmf_trouble.sh PARTET MPIEXEC
set -euo pipefail
partet=$1 mpiexec=$2
work=$(mktemp -d)
trap 'umount "$work/full" 2> /dev/null || true; rm -rf "$work"' EXIT
cd "$work"
mkdir out
"$partet" generate genus3 --faces 4000 -o in.off > /dev/null
"$partet" generate two_spheres --faces 4000 -o other.off > /dev/null
"$mpiexec" -n 2 "$partet" mesh in.off -o out/m.xdmf --pieces 4 --quiet
mkdir before && cp out/* before/
"$mpiexec" -n 2 "$partet" mesh in.off -o out/t --pieces 4 --quiet
cp out/t.* before/

expect_refused() {  # NAME EXPECTED-MESSAGE-PART
  local status=0
  grep -q "$2" log || { echo "FAIL: $1: the error does not say '$2':"; cat log; exit 1; }
  for f in before/*; do
    cmp -s "$f" "out/$(basename "$f")" || { echo "FAIL: $1: $(basename "$f") changed"; exit 1; }
  done
  [ "$(ls out | wc -l)" -eq "$(ls before | wc -l)" ] || { echo "FAIL: $1: files left: $(ls out)"; exit 1; }
  echo "ok: $1: refused on every rank, previous set kept: $(grep -o "rank 1[^;]*" log | head -n 1)"
}

if PARTET_INJECT_FAILURE=worker:lose-block "$mpiexec" -n 2 "$partet" mesh other.off -o out/m.xdmf --pieces 4 \
  --quiet 2> log; then
  echo "FAIL: lost: a lost block exited 0"; exit 1
fi
expect_refused lost "rank 1 could not take its part of the mesh"

if PARTET_TEST_ASSEMBLE=1 PARTET_INJECT_FAILURE=worker:lose-block "$mpiexec" -n 2 "$partet" mesh other.off -o out/t --pieces 4 \
  --format tetgen --quiet 2> log; then
  echo "FAIL: lost-rows: a lost block exited 0"; exit 1
fi
expect_refused lost-rows "rank 1 did not receive its block of the .node file's rows"

if PARTET_INJECT_FAILURE=worker:lose-block "$mpiexec" -n 2 "$partet" mesh other.off -o out/t --pieces 4 \
  --quiet 2> log; then
  echo "FAIL: lost-neigh: a lost block exited 0"; exit 1
fi
expect_refused lost-neigh "rank 1 did not receive the faces its bulk of piece [0-9]* shares with the rest of the mesh"

for format in tetgen vtu; do
  if PARTET_INJECT_FAILURE=worker:lose-points "$mpiexec" -n 2 "$partet" mesh other.off -o out/t --pieces 4 \
    --format $format --quiet 2> log; then
    echo "FAIL: lost-points-$format: lost points exited 0"; exit 1
  fi
  expect_refused lost-points-$format "rank 1 did not receive its share of the input's points to format"
done

if PARTET_INJECT_FAILURE=worker:lose-block "$mpiexec" -n 2 "$partet" mesh other.off -o out/m.pvtu --pieces 4 \
  --quiet 2> log; then
  echo "FAIL: lost-vtu: a lost block exited 0"; exit 1
fi
expect_refused lost-vtu "rank 1 did not receive the content of 'out/m_[a-z0-9]*.vtu'"

if PARTET_INJECT_FAILURE=worker:lose-block "$mpiexec" -n 2 "$partet" mesh other.off -o out/p --pieces 4 \
  --format msh-parts --quiet 2> log; then
  echo "FAIL: lost-msh-parts: a lost block exited 0"; exit 1
fi
expect_refused lost-msh-parts "rank 1 did not receive the content of 'out/p_[0-9]*.msh'"

for format in tetgen vtu medit msh-binary pvtu msh-parts; do
  if PARTET_INJECT_FAILURE=worker:write-out-of-memory "$mpiexec" -n 2 "$partet" mesh other.off -o out/w --pieces 4 \
    --format $format --quiet 2> log; then
    echo "FAIL: oom-$format: running out of memory exited 0"; exit 1
  fi
  expect_refused oom-$format "rank 1 ran out of memory (at [0-9]* MB"
done

if ! unshare -m true 2> /dev/null; then
  echo "skipped: not-shared needs unshare -m"; exit 77
fi
if "$mpiexec" --oversubscribe -n 1 "$partet" mesh other.off -o "$work/out/m.xdmf" --pieces 4 --quiet \
  : -n 1 unshare -m sh -c "mount -t tmpfs tmpfs '$work/out' && exec '$partet' mesh other.off -o '$work/out/m.xdmf' --pieces 4 --quiet" \
  2> log; then
  echo "FAIL: not-shared: a rank writing elsewhere exited 0"; exit 1
fi
expect_refused not-shared "rank 1 does not see the output directory"

mkdir alone
"$partet" mesh in.off -o alone/m.pvtu --pieces 4 --quiet
"$mpiexec" --oversubscribe -n 1 "$partet" mesh in.off -o "$work/out/m.pvtu" --pieces 4 --quiet --report report.json \
  : -n 1 unshare -m sh -c "mount -t tmpfs tmpfs '$work/out' && exec '$partet' mesh in.off -o '$work/out/m.pvtu' --pieces 4 --quiet"
for f in alone/*; do cmp "$f" "out/$(basename "$f")" || { echo "FAIL: not-shared-pvtu: $(basename "$f") differs"; exit 1; }; done
/usr/bin/python3 -c "
import json
report = json.load(open('report.json'))
written = [r['piece_files_written'] for r in report['rank']]
assert written == [5, 0], written
assert not report['assembled_on_rank0'], 'the mesh was assembled'"
echo "ok: not-shared-pvtu: rank 0 wrote the 5 piece files rank 1 could not see (from rank 1's parts: the mesh was not assembled), the same bytes as 1 rank's"
rm out/m.pvtu out/m_*.vtu

# The output directory fills up during the write (a small tmpfs) and stays full: the run must end
# with the disk's error on every rank and leave nothing there. (Each tmpfs is too small for the
# least room these files take, which partet would refuse before the meshing: the hook has rank 0
# see plenty, as on a disk another job fills during the write; after the first failure it sees
# more, so it writes again (every rank must join the second try), then fails again and waits
# until the short --wait-for-space ends. The room checks:
# tests/cli/disk_space.sh; the mesh written again once room is made: tests/cli/full_ext4.sh.)
# The wait (4.8 s) counts from the first write, so it must outlast both writes on a loaded
# machine: at 1.2 s, a CI run's second write began after it and was not waited for.
expect_full() {  # NAME TMPFS-SIZE OUTPUT ERROR-PATTERN [OPTION...]
  mount -t tmpfs -o size="$2" tmpfs full
  if PARTET_TEST_FREE_DISK_MB=1e9,1e9,1e9,2e9 timeout 120 "$mpiexec" -n 2 -x PARTET_TEST_FREE_DISK_MB "$partet" mesh big.off \
    -o "$3" --pieces 4 --wait-for-space 0.08 "${@:5}" 2> log; then
    umount full; echo "FAIL: $1: a full disk exited 0"; exit 1
  fi
  left=$(ls full)
  umount full
  grep -q "$4" log || { echo "FAIL: $1: the error:"; cat log; exit 1; }
  [ "$(grep -c "ran out while the files were written" log)" = 2 ] && [ "$(grep -c "writing again" log)" = 1 ] \
    || { echo "FAIL: $1: not written twice:"; cat log; exit 1; }
  [ -z "$left" ] || { echo "FAIL: $1: files left: $left"; exit 1; }
  echo "ok: $1: $(grep -o "$4" log | head -n 1), tried twice, nothing left"
}
mkdir full
"$partet" generate genus3 --faces 40000 -o big.off > /dev/null
# full: while rank 0 writes the lines the ranks formatted.
expect_full full 3m full/m "cannot write 'full/m\.[a-z]*': No space left on device"
# full-hdf5: while both ranks write the XDMF set's HDF5 file at once.
expect_full full-hdf5 1m full/m.xdmf "cannot write 'full/m\.h5'.*No space left on device"
# full-pvtu: while both ranks write their piece files.
expect_full full-pvtu 1m full/m.pvtu "cannot write 'full/m_[a-z0-9]*\.vtu': No space left on device"
# full-msh: while rank 0 writes one MSH file, rank 1 sending the rows of the bulks it keeps.
expect_full full-msh 2m full/m.msh "cannot write 'full/m\.msh': No space left on device"
# full-vtu: while rank 0 writes one .vtu file, compressing the rows rank 1 sends.
expect_full full-vtu 512k full/m.vtu "cannot write 'full/m\.vtu': No space left on device"
# full-msh-parts: while both ranks write their MSH partitions (rank 1 from the bulks it keeps).
expect_full full-msh-parts 2m full/m "cannot write 'full/m_[0-9]*\.msh': No space left on device" --format msh-parts
