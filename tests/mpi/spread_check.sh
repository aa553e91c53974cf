#!/usr/bin/env bash
# `mesh --check` on several ranks with the mesh left where its parts are. When rank 0 has the
# memory, it assembles the mesh and checks it in memory (faster); else (here: 1 MB available,
# PARTET_TEST_AVAILABLE_MB) it does not assemble the mesh to check it: every rank reads back its
# part of the files just written (TetGen's, or the XDMF set's) before they are published. The report's check equals the assembled path's (the same
# run with PARTET_TEST_ASSEMBLE): the counts, volumes and the quality of the whole mesh, of the
# seam zone and of the rest (sums to rounding, the rest exactly), and the files are the same
# bytes. A check that fails, or a rank out of memory or stopped while checking, publishes nothing
# and leaves the previous set in place. A check only rank 0's memory can do, while it is short, is
# refused before the meshing. 2 ranks, and 4 oversubscribed.
# Usage: spread_check.sh PARTET MPIEXEC
set -uo pipefail
partet=$1 mpiexec=$2
source "$(dirname "$0")/../harness.sh"
cd "$work"
"$partet" generate genus3 --faces 20000 -o g3.off > /dev/null
# The check's figures in two reports: equal, the averages to 1e-9.
same_check() {
  /usr/bin/python3 - "$1" "$2" << 'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
assert a["assembled_on_rank0"] is False and b["assembled_on_rank0"] is True, "assembled: %s %s" % (
    a["assembled_on_rank0"], b["assembled_on_rank0"])
assert "check" in a["stage_seconds"], "no check stage"
for zone in ("all", "seam_zone", "elsewhere"):
    qa, qb = a["quality"][zone], b["quality"][zone]
    assert set(qa) == set(qb), zone
    for key in qa:
        x, y = qa[key], qb[key]
        if key.endswith("avg"):
            assert abs(x - y) <= 1e-9 * max(1.0, abs(y)), (zone, key, x, y)
        else:
            assert x == y, (zone, key, x, y)
assert a["quality"]["all"]["tets"] == a["counts"]["output_tets"] > 0, "tets"
assert a["quality"]["seam_zone"]["tets"] > 0 and a["quality"]["elsewhere"]["tets"] > 0, "zones"
assert a["quality"]["seam_zone"]["tets"] + a["quality"]["elsewhere"]["tets"] == a["counts"]["output_tets"], "zones' sum"
print("%d tets, %d in the seam zone" % (a["counts"]["output_tets"], a["quality"]["seam_zone"]["tets"]))
PY
}

for n in 2 4; do
  launch=("$mpiexec" -n $n --oversubscribe)
  # 1. TetGen's files, and the XDMF set, checked where they are, as the assembled path checks them.
  for format in tetgen xdmf; do
    PARTET_TEST_AVAILABLE_MB=1 "${launch[@]}" -x PARTET_TEST_AVAILABLE_MB "$partet" mesh g3.off -k 5 --format $format \
      --check -o s$n$format --report s.json > s.log 2>&1 &&
      PARTET_TEST_ASSEMBLE=1 "${launch[@]}" -x PARTET_TEST_ASSEMBLE "$partet" mesh g3.off -k 5 --format $format \
        --check -o a$n$format --report a.json > a.log 2>&1 || { bad "$n ranks, $format: a run failed: $(tail -n 3 s.log a.log)"; continue; }
    if ! grep -q "check passed" s.log; then bad "$n ranks, $format: no 'check passed': $(tail -n 3 s.log)"
    elif ! out=$(same_check s.json a.json 2>&1); then bad "$n ranks, $format: $out"
    elif [ $format = tetgen ] && ! cat s$n$format.{node,ele,face,neigh} | cmp -s - <(cat a$n$format.{node,ele,face,neigh}); then
      bad "$n ranks, $format: the files differ from the assembled path's"
    elif ls -A | grep -q "tmp-"; then bad "$n ranks, $format: temporaries left: $(ls -A | grep tmp-)"
    else ok "$n ranks, $format: checked on the ranks, not assembled, as the assembled check finds it ($out)"; fi
  done
done

# A rank that cannot open the files (a node without rank 0's output directory; rank 1 here, of
# 3) sits the check out; the others check the whole set.
PARTET_INJECT_FAILURE=worker:output-unseen PARTET_TEST_AVAILABLE_MB=1 "$mpiexec" -n 3 --oversubscribe "$partet" mesh g3.off -k 5 \
  --check -o u --report u.json > u.log 2>&1 &&
  PARTET_TEST_ASSEMBLE=1 "$mpiexec" -x PARTET_TEST_ASSEMBLE -n 3 --oversubscribe "$partet" mesh g3.off -k 5 --check -o ua \
    --report ua.json > ua.log 2>&1 || bad "a rank without the files: a run failed: $(tail -n 3 u.log ua.log)"
if ! out=$(same_check u.json ua.json 2>&1); then bad "a rank without the files: $out"
elif ! grep -q "rank 1 cannot open .*the other ranks check the files" u.log; then bad "a rank without the files: no warning: $(tail -n 3 u.log)"
else ok "a rank without the files (1 of 3) sat the check out; the others found what the assembled check finds ($out)"; fi

# 2. With the memory for it (this machine, this small mesh), rank 0 assembles the mesh and checks
# it in memory.
"$mpiexec" -n 2 "$partet" mesh g3.off -k 5 --check -o m --report m.json > m.log 2>&1 || bad "the run with memory failed"
if [ "$(python3 -c "import json; print(json.load(open('m.json'))['assembled_on_rank0'])")" = True ] && grep -q "check passed" m.log; then
  ok "with the memory for it: assembled and checked in memory"
else bad "with the memory for it: $(tail -n 3 m.log)"; fi

# 3. A check that fails: the run fails saying why, and the previous set stays as it was.
"$mpiexec" -n 2 "$partet" mesh g3.off -k 5 -o kept --quiet || bad "the first run failed"
md5=$(cat kept.node kept.ele kept.face kept.neigh | md5sum)
PARTET_INJECT_FAILURE=check:inverted-tet PARTET_TEST_AVAILABLE_MB=1 "$mpiexec" -n 2 "$partet" mesh g3.off -k 4 --check -o kept > f.log 2>&1
code=$?
if [ $code = 0 ]; then bad "a failed check: exit 0"
elif ! grep -q "the result failed its own check: 1 tets are inverted" f.log; then bad "a failed check: $(tail -n 3 f.log)"
elif [ "$(cat kept.node kept.ele kept.face kept.neigh | md5sum)" != "$md5" ]; then bad "a failed check: the previous set changed"
elif ls -A | grep -q "tmp-"; then bad "a failed check: temporaries left: $(ls -A | grep tmp-)"
else ok "a failed check: exit $code, '$(grep -o 'the result failed its own check: [^;]*' f.log | head -n 1)', the previous set intact"; fi

# 4. A rank out of memory while it checks (the others wait for it in the check's exchanges): the
# job ends at once saying which rank, and nothing is published.
PARTET_INJECT_FAILURE=check:out-of-memory PARTET_TEST_AVAILABLE_MB=1 timeout -k 10 120 "$mpiexec" -n 2 "$partet" mesh g3.off -k 4 --check -o oom > o.log 2>&1
code=$?
sleep 1  # the reaper removes the temporaries of the process the abort ended
if [ $code = 0 ] || [ $code = 124 ]; then bad "a rank out of memory while checking: exit $code: $(tail -n 3 o.log)"
elif ! grep -q "out of memory on rank 1 while checking" o.log; then bad "a rank out of memory while checking: $(tail -n 5 o.log)"
elif ls oom.* > /dev/null 2>&1; then bad "a rank out of memory while checking: left $(ls oom.*)"
else ok "a rank out of memory while checking: exit $code, '$(grep -o 'out of memory on rank 1[^;]*' o.log | head -n 1)', nothing published or left"; fi
# 4b. A rank stopped while it checks (SIGSTOP once its files are read back): the others' watch
# ends the job once they have waited PARTET_TEST_COLLECTIVE_S in one step, nothing is published,
# and the previous set stays as it was.
# (check:stop-at-start: stopped before the ranks first meet in the check.)
for stop in check:stop check:stop-at-start; do
  start=$SECONDS
  PARTET_INJECT_FAILURE=$stop PARTET_TEST_COLLECTIVE_S=3 PARTET_TEST_AVAILABLE_MB=1 timeout -k 10 120 "$mpiexec" -n 2 "$partet" mesh g3.off -k 4 --check -o kept > s.log 2>&1
  code=$? elapsed=$((SECONDS - start))
  sleep 1  # the reaper removes the temporaries of the process the abort ended
  if [ $code = 0 ] || [ $code = 124 ]; then bad "$stop: a rank stopped while checking: exit $code: $(tail -n 3 s.log)"
  elif ! grep -q "has waited 3 s for the other ranks in one step of checking" s.log; then bad "$stop: a rank stopped while checking: $(tail -n 5 s.log)"
  elif [ "$(cat kept.node kept.ele kept.face kept.neigh | md5sum)" != "$md5" ]; then bad "$stop: a rank stopped while checking: the previous set changed"
  elif ls -A | grep -q "tmp-"; then bad "$stop: a rank stopped while checking: temporaries left: $(ls -A | grep tmp-)"
  else ok "$stop: a rank stopped while checking: exit $code after $elapsed s, '$(grep -o 'rank 0 has waited 3 s[^:]*' s.log | head -n 1)', the previous set intact"; fi
done
# 5. A check only rank 0's memory can do (no TetGen files or XDMF set to read back; --quality,
# which assembles the mesh to polish it) while that memory is already short: refused before any
# piece is meshed, as a usage error that says what to do, and nothing is written.
for case in "--format vtu,msh|add --format tetgen (or xdmf)" "--quality 1.5|--quality assembles the mesh on rank 0"; do
  options=${case%%|*} advice=${case#*|}
  # shellcheck disable=SC2086
  PARTET_TEST_AVAILABLE_MB=1 timeout -k 10 120 "$mpiexec" -n 2 -x PARTET_TEST_AVAILABLE_MB "$partet" mesh g3.off -k 4 $options \
    --check --verbose -o short > r.log 2>&1
  code=$?
  if [ $code != 2 ]; then bad "$options, too little memory to check: exit $code, not 2: $(tail -n 3 r.log)"
  elif ! grep -q "in rank 0's memory needs about .* MB and 1 MB are available; .*$advice" r.log; then
    bad "$options, too little memory to check: $(grep error r.log | head -n 1)"
  elif grep -q "piece 0\|tetgen done" r.log; then bad "$options, too little memory to check: refused only after meshing"
  elif ls -A | grep -q "short\|tmp-"; then bad "$options, too little memory to check: left $(ls -A | grep 'short\|tmp-')"
  else ok "$options, too little memory to check: refused before meshing, exit 2, '...$advice...'"; fi
done
summary
