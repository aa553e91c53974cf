#!/usr/bin/env bash
# partet check on TetGen files under mpirun, each rank reading a share of every file's bytes: on
# 2, 3 and 4 ranks it must agree with the check in one process (vertices, tets, boundary faces,
# volume, V-E+F-T), and on 2 ranks it must catch each kind of damage done to the text: an inverted
# tet, a boundary face turned over, a wrong neighbour, a missing and a repeated row, files from
# two runs, a set without partet's ID, a missing file; --report needs one process; a rank out of
# memory in a check step ends the job, and so does a rank stopped in one.
# Usage: check_tetgen_ranks.sh PARTET MPIEXEC
set -euo pipefail
partet=$1 mpiexec=$2 tests=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
"$partet" generate two_spheres --faces 4000 -o in.off > /dev/null
"$mpiexec" -n 2 "$partet" mesh in.off -o m --pieces 4 --quiet
"$partet" check in.off m --json > serial.json
# 4 ranks also in passes of 16 KB of records (10-25 per step of the check) and reads of 16 KB of
# text, as a mesh of millions of tets is checked.
for n in 2 3 4 4p; do
  if [ $n = 4p ]; then
    PARTET_TEST_CHECK_PASS_BYTES=16384 "$mpiexec" -n 4 "$partet" check in.off m --json > n$n.json
  else
    "$mpiexec" -n $n "$partet" check in.off m --json > n$n.json
  fi
  label="$n ranks"
  [ $n = 4p ] && label="4 ranks in passes of 16 KB"
  "$tests/same_check.py" serial.json n$n.json "$label" "one process"
done

# damage NAME EXTENSION PYTHON-STATEMENTS EXPECTED: copies the set to d.*, runs the statements on
# `lines` (the text of d.EXTENSION, split at newlines; lines[0] is the header, lines[i] row i - 1),
# and the check on 2 ranks must fail saying EXPECTED (each step in passes of 16 KB).
damage() {
  for e in node ele face neigh; do cp m.$e d.$e; done
  /usr/bin/python3 -c "
lines = open('d.$2').read().split('\n')
$3
open('d.$2', 'w').write('\n'.join(lines))"
  if PARTET_TEST_CHECK_PASS_BYTES=16384 "$mpiexec" -n 2 "$partet" check in.off d > out 2>&1; then
    echo "FAIL: $1 passed the check"; cat out; exit 1
  fi
  grep -q "$4" out || { echo "FAIL: $1: no '$4':"; cat out; exit 1; }
  echo "ok: $1: $(grep -m 2 "VIOLATION\|error" out | tr '\n' ' ')"
}
swap() {  # ROW A B: python statements swapping values A and B (after the index) of row ROW
  echo "r = lines[$1 + 1].split(); r[$2 + 1], r[$3 + 1] = r[$3 + 1], r[$2 + 1]; lines[$1 + 1] = '  '.join(r)"
}
damage "inverted tet" ele "$(swap 700 0 1)" "tets are inverted"
damage "face turned over" face "$(swap 5 1 2)" "triangles of the .face file face into their tet"
damage "wrong neighbour" neigh "r = lines[900].split(); r[1] = '-1' if r[1] != '-1' else '0'; lines[900] = ' '.join(r)" \
  "tet faces have another neighbour in the .neigh file"
damage "missing point row" node "del lines[1200]" "d.node has no row of index 1199"
damage "repeated tet row" ele "lines.insert(801, lines[801])" "d.ele has index 800 twice"
damage "files of two runs" face "lines[-2] = lines[-2][:-4] + '0000'" "come from different runs"
damage "a set without partet's ID" neigh "lines[-2] = '# written elsewhere'" "only sets partet wrote"
rm d.neigh
if "$mpiexec" -n 2 "$partet" check in.off d > out 2>&1; then echo "FAIL: a missing .neigh passed"; exit 1; fi
grep -q "cannot open d.neigh" out || { echo "FAIL: a missing .neigh:"; cat out; exit 1; }
echo "ok: a missing file: $(grep -m 1 error out)"
if "$mpiexec" -n 2 "$partet" check in.off m --report r.json > out 2>&1; then echo "FAIL: --report on ranks"; exit 1; fi
grep -q "need the whole mesh in one process" out || { echo "FAIL: --report on ranks:"; cat out; exit 1; }
echo "ok: --report needs one process"
# A rank out of memory in a check step (the others wait for it in the exchanges) ends the whole
# job at once, saying which rank, instead of leaving the others waiting for ever.
if PARTET_INJECT_FAILURE=check:out-of-memory timeout -k 10 60 "$mpiexec" -n 3 "$partet" check in.off m > out 2>&1; then
  echo "FAIL: a rank out of memory passed the check"; exit 1
fi
grep -q "out of memory on rank 1" out || { echo "FAIL: no 'out of memory on rank 1' (still waiting?):"; cat out; exit 1; }
echo "ok: a rank out of memory ends the job: $(grep -m 1 'out of memory' out)"
# A rank that stops in a check step (SIGSTOP once its files are read: it neither fails nor dies,
# so the launcher sees nothing) ends the job once the others have waited PARTET_TEST_COLLECTIVE_S
# in one step of the check's exchanges, saying so, instead of leaving them waiting for ever.
# The same for a rank stopped as the check starts, before the ranks first meet.
for stop in check:stop check:stop-at-start; do
  start=$SECONDS
  if PARTET_INJECT_FAILURE=$stop PARTET_TEST_COLLECTIVE_S=3 timeout -k 10 60 "$mpiexec" -n 2 "$partet" check in.off m > out 2>&1; then
    echo "FAIL: $stop: a stopped rank passed the check"; exit 1
  fi
  elapsed=$((SECONDS - start))
  grep -q "has waited 3 s for the other ranks in one step of checking '[^']*m'" out ||
    { echo "FAIL: $stop: no 'has waited 3 s ... checking' (still waiting?):"; cat out; exit 1; }
  [ "$elapsed" -le 30 ] || { echo "FAIL: $stop: a stopped rank's check took $elapsed s (limit 30: 3 s of waiting)"; exit 1; }
  echo "ok: $stop: a stopped rank ends the check in $elapsed s: $(grep -m 1 'has waited' out | cut -c1-120)"
done
