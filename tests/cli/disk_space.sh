#!/usr/bin/env bash
# Room on the output's filesystem (io/output_size.hpp), with the room rank 0 sees set by
# PARTET_TEST_FREE_DISK_MB (the real full disk: full_ext4.sh):
# 1. less than the smallest files the input's mesh can have: refused before any piece is meshed
#    (exit 2), nothing written, the previous mesh kept;
# 2. every format's files take at least the room partet asks for (a run given exactly the room its
#    files took writes them), and every format but the compressed .vtu sets asks for some;
# 3. a disk that fills up during the meshing: the mesh waits for room, says so, and is written
#    (and checked) once room is made;
# 4. still full when --wait-for-space runs out: exit 1, nothing written, the previous mesh kept;
#    and a disk smaller in all than the files (PARTET_TEST_DISK_CAPACITY_MB): no wait, the same;
# 5. a quota that runs out during the write (EDQUOT, set by PARTET_TEST_QUOTA_WRITES: the free
#    space does not show it): the mesh is kept and written again after the pause, the same files.
# Usage: disk_space.sh PARTET [LAUNCH...]
set -uo pipefail
partet=$(realpath "$1")
shift
launch=("$@")
source "$(dirname "$0")/../harness.sh"
cd "$work"
"$partet" generate genus3 --faces 4000 -o in.off > /dev/null
"${launch[@]}" "$partet" mesh in.off -o m --pieces 3 --quiet || bad "first run"
md5sum m.* > before.md5

# run_free ROOM ARGS...: partet mesh ARGS seeing ROOM (a list: one value per look) MB free.
run_free() {
  local room=$1
  shift
  if [ ${#launch[@]} -gt 0 ]; then
    env PARTET_TEST_FREE_DISK_MB="$room" "${launch[@]}" -x PARTET_TEST_FREE_DISK_MB -x PARTET_TEST_QUOTA_WRITES \
      -x PARTET_TEST_DISK_CAPACITY_MB "$partet" mesh "$@"
  else PARTET_TEST_FREE_DISK_MB="$room" "$partet" mesh "$@"; fi
}
kept() { md5sum --quiet -c before.md5 && [ -z "$(ls -A | grep -v -x -e m.node -e m.ele -e m.face -e m.neigh \
  -e in.off -e before.md5 -e log -e 'f_.*' -e 'g_.*' -e 'w\..*')" ]; }

# 1. Refused up front.
run_free 0.01 in.off -o m --pieces 3 --verbose > log 2>&1
code=$?
if [ $code = 2 ] && grep -q "no room for the output: .* take at least 1 MB as tetgen, and $work has 0 MB free: make room there, or write elsewhere (-o)\. Nothing was meshed\." log &&
   ! grep -q "piece" log && kept; then
  ok "a full disk is refused before the meshing: $(grep -o 'the files of a mesh of these [0-9]* faces[^)]*)' log)"
else
  bad "refusal up front (exit $code):"; cat log
fi

# 2. Every format's files take at least what partet asks for.
formats="tetgen vtu pvtu msh msh-binary msh-parts msh-parts-binary medit xdmf"
for format in $formats; do
  mkdir "f_$format" "g_$format"
  "${launch[@]}" "$partet" mesh in.off -o "f_$format/m" --format "$format" --pieces 3 --quiet > log 2>&1 || { bad "$format: plain run"; continue; }
  room=$(du -b -c "f_$format"/m* | awk 'END {printf "%.6f", $1 / 1048576}')
  if ! run_free "1e9,$room" in.off -o "g_$format/m" --format "$format" --pieces 3 --wait-for-space 0 > log 2>&1; then
    bad "$format: its own files' room ($room MB) was not enough:"; cat log; continue
  fi
  run_free "1e9,0.000001" in.off -o "g_$format/n" --format "$format" --pieces 3 --wait-for-space 0 > log 2>&1
  code=$?
  case $format in
    vtu | pvtu) [ $code = 0 ] && ok "$format: written in its own $room MB; asks for no room (compressed)" || bad "$format: no room asked, yet exit $code" ;;
    *) if [ $code = 1 ] && grep -q "nothing was written; make room there and run again" log && [ -z "$(ls "g_$format" | grep '^n')" ]; then
         ok "$format: written in its own $room MB; asks for at least $(grep -o 'take at least [0-9]* MB' log | cut -d' ' -f4-)"
       else bad "$format: a full disk at the write (exit $code):"; cat log; fi ;;
  esac
done

# 3. The disk fills up during the meshing: the mesh waits, then is written and checked.
run_free "1e9,0.000001,0.000001,0.000001,1e9" in.off -o w --pieces 3 --check > log 2>&1
code=$?
if [ $code = 0 ] && grep -q "warning: $work has 0 MB free, and the files of this mesh ([0-9]* points, [0-9]* tets) take at least [0-9]* MB as tetgen: waiting up to 20 min for room (--wait-for-space)" log &&
   grep -q "warning: room at $work after [0-9]* s: writing" log && grep -q "check passed" log && [ -s w.node ]; then
  ok "a disk full after the meshing: waited, then written and checked"
else
  bad "waiting for room (exit $code):"; cat log
fi

# 4. Still full when the wait ends.
run_free "1e9,0.000001" in.off -o m --pieces 3 --wait-for-space 0.005 > log 2>&1
code=$?
if [ $code = 1 ] && grep -q "error: $work has 0 MB free, .* after waiting 0 s: nothing was written; make room there and run again, with --checkpoint DIR so that a rerun need not mesh the pieces again" log && kept; then
  ok "still full after --wait-for-space: exit 1, nothing written, the previous mesh kept"
else
  bad "giving up the wait (exit $code):"; cat log
fi
# A disk smaller in all than the files: no room can be made there, so no wait (20 min by default).
started=$SECONDS
PARTET_TEST_DISK_CAPACITY_MB=0.1 run_free "1e9,0.000001" in.off -o m --pieces 3 > log 2>&1
code=$?
if [ $code = 1 ] && [ $((SECONDS - started)) -lt 120 ] && ! grep -q "waiting up to" log &&
   grep -q "error: $work has 0 MB free, and the files of this mesh ([0-9]* points, [0-9]* tets) take at least [0-9]* MB as tetgen; the disk at $work holds 0 MB in all, so no room can be made there for them: nothing was written; write elsewhere (-o) and run again, with --checkpoint DIR" log && kept; then
  ok "a disk smaller than the files: exit 1 at once, nothing written, the previous mesh kept"
else
  bad "a disk smaller than the files (exit $code):"; cat log
fi
export -n PARTET_TEST_DISK_CAPACITY_MB 2> /dev/null

# 5. The quota runs out during the write: tried again after the pause, then written.
PARTET_TEST_QUOTA_WRITES=1 run_free 1e9 in.off -o q --pieces 3 > log 2>&1
code=$?
if [ $code = 0 ] && [ "$(grep -c "warning: the quota ran out while the files were written (cannot write 'q\.[a-z]*': Disk quota exceeded); the mesh is kept: trying again every minute for up to 20 min (--wait-for-space)" log)" = 1 ] &&
   [ "$(grep -c "warning: writing again after 0 s" log)" = 1 ]; then
  same=1
  for f in node ele face neigh; do cmp -s m.$f q.$f || same=0; done
  [ $same = 1 ] && ok "a quota that ran out during the write: tried again, then the same files as a plain run" ||
    bad "the files written after the quota ran out differ"
else
  bad "a quota running out during the write (exit $code):"; cat log
fi
export -n PARTET_TEST_QUOTA_WRITES 2> /dev/null
summary
