#!/usr/bin/env bash
# The XDMF set, a .pvtu set, MSH partitions, TetGen's files, a .vtu, a MEDIT and an MSH file from
# several ranks: rank 0 does not assemble the mesh; every bulk's rows, piece file and partition
# file are written by the rank that meshed it, and its rows in the single files are streamed from
# there to rank 0 (the report says assembled_on_rank0: false). The sets must hold exactly what the
# assembled path writes (the same run with PARTET_TEST_ASSEMBLE, as a check or a polish would
# make it): every dataset equal, the HDF5 files, every piece and partition file, the four TetGen
# files, the .vtu, the .mesh and the .msh file byte for byte, the .pvtu index naming the same
# files; `partet check` passes on each set. Shapes with one solid and with two; 2 and 4 ranks; a
# .pvtu set alone, binary MSH partitions alone, TetGen's files alone, a binary MSH file alone; two
# runs at once on one prefix.
# Usage: spread_output.sh PARTET MPIEXEC
set -uo pipefail
partet=$1 mpiexec=$2
source "$(dirname "$0")/../harness.sh"
cd "$work"
same_sets() {  # A B: every dataset of the two sets' HDF5 files equal
  /usr/bin/python3 - "$1" "$2" << 'PY'
import sys, h5py, numpy as np
a, b = sys.argv[1], sys.argv[2]
for suffix in (".h5", "_boundary.h5"):
    with h5py.File(a + suffix, "r") as fa, h5py.File(b + suffix, "r") as fb:
        names = []
        fa.visit(lambda n: names.append(n) if isinstance(fa[n], h5py.Dataset) else None)
        assert names, "no datasets in " + a + suffix
        for n in names:
            assert n in fb, n + " missing in " + b + suffix
            assert fa[n].dtype == fb[n].dtype and np.array_equal(fa[n][()], fb[n][()]), n + " differs"
PY
}
same_numbered() {  # A B EXT WHAT: the files A_*.EXT and B_*.EXT byte for byte, as many
  local a=$1 b=$2 files=0 f
  for f in ${a}_*.$3; do
    cmp -s $f ${b}_${f#${a}_} || { echo "$f differs from ${b}_${f#${a}_}"; return 1; }
    files=$((files + 1))
  done
  [ $files -gt 0 ] && [ $files = $(ls ${b}_*.$3 | wc -l) ] || { echo "$files $4, against $(ls ${b}_*.$3 | wc -l)"; return 1; }
  echo "$files $4"
}
same_piece_files() {  # A B: the .pvtu sets A.pvtu and B.pvtu name the same piece files, byte for byte
  cmp -s <(sed "s/\"${1}_/\"X_/" $1.pvtu) <(sed "s/\"${2}_/\"X_/" $2.pvtu) || { echo "the .pvtu indexes differ"; return 1; }
  same_numbered $1 $2 vtu "piece files"
}
same_partitions() { same_numbered $1 $2 msh "partition files"; }  # A B: the MSH partition files
same_files() {  # A B: the TetGen, .vtu, MEDIT and MSH files of the two prefixes byte for byte (those A has)
  local x n=0
  for x in node ele face neigh vtu mesh msh; do
    [ -e $1.$x ] || continue
    cmp -s $1.$x $2.$x || { echo "$1.$x differs from $2.$x"; return 1; }
    n=$((n + 1))
  done
  [ $n -gt 0 ] || { echo "no file at $1"; return 1; }
}
assembled() { /usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["assembled_on_rank0"])' "$1"; }
regions() { /usr/bin/python3 -c 'import h5py,sys; print(int(h5py.File(sys.argv[1],"r")["/Mesh/mesh/region"][()].max()))' "$1"; }
for shape in genus3 two_spheres nested; do
  "$partet" generate $shape --faces 6000 -o $shape.off > /dev/null || exit 1
  for n in 2 4; do
    name="$shape on $n ranks"
    formats=xdmf,pvtu,tetgen,vtu,medit,msh,msh-parts
    "$mpiexec" -n $n --oversubscribe "$partet" mesh $shape.off -k 6 --format $formats -o s_${shape}_$n --report s.json --quiet ||
      { bad "$name: the spread run failed"; continue; }
    PARTET_TEST_ASSEMBLE=1 "$mpiexec" -x PARTET_TEST_ASSEMBLE -n $n --oversubscribe "$partet" mesh $shape.off -k 6 --format $formats -o a_${shape}_$n --report a.json --quiet ||
      { bad "$name: the assembled run failed"; continue; }
    [ "$(assembled s.json)/$(assembled a.json)" = False/True ] ||
      { bad "$name: assembled on rank 0: spread run $(assembled s.json), assembling $(assembled a.json)"; continue; }
    if ! out=$(same_sets s_${shape}_$n a_${shape}_$n 2>&1); then bad "$name: the sets differ: $out"; continue; fi
    bytes=same
    cmp -s s_${shape}_$n.h5 a_${shape}_$n.h5 && cmp -s s_${shape}_${n}_boundary.h5 a_${shape}_${n}_boundary.h5 || bytes=different
    [ $bytes = same ] || { bad "$name: the HDF5 files' datasets agree but their bytes differ"; continue; }
    if ! out=$(same_piece_files s_${shape}_$n a_${shape}_$n); then bad "$name: $out"; continue; fi
    if ! parts=$(same_partitions s_${shape}_$n a_${shape}_$n); then bad "$name: $parts"; continue; fi
    if ! err=$(same_files s_${shape}_$n a_${shape}_$n); then bad "$name: $err"; continue; fi
    for set in s_${shape}_$n.xdmf s_${shape}_$n.pvtu s_${shape}_$n s_${shape}_$n.vtu s_${shape}_$n.mesh s_${shape}_${n}_1.msh; do
      "$mpiexec" -n 2 "$partet" check $shape.off $set > check.log 2>&1 || { bad "$name: partet check $set failed: $(tail -n 3 check.log)"; continue 2; }
    done
    ok "$name: written from the owners of its parts, the assembled path's sets, TetGen, .vtu, MEDIT and MSH files byte for byte ($(regions s_${shape}_$n.h5) solid(s), $out, $parts), checks passed"
  done
done
# A .pvtu set alone, on 3 ranks, against the same set written assembled.
"$mpiexec" -n 3 --oversubscribe "$partet" mesh genus3.off -k 5 --format pvtu -o p_alone --report s.json --quiet &&
  PARTET_TEST_ASSEMBLE=1 "$mpiexec" -x PARTET_TEST_ASSEMBLE -n 3 --oversubscribe "$partet" mesh genus3.off -k 5 --format pvtu -o a_alone --report a.json --quiet ||
  bad "pvtu alone: a run failed"
if [ "$(assembled s.json)/$(assembled a.json)" != False/True ]; then
  bad "pvtu alone: assembled on rank 0: $(assembled s.json), assembling $(assembled a.json)"
elif ! out=$(same_piece_files p_alone a_alone); then
  bad "pvtu alone: $out"
else
  ok "pvtu alone on 3 ranks: not assembled, the assembled path's set byte for byte ($out)"
fi
# Binary MSH partitions alone, on 3 ranks, with K=7 (some pieces' bulks stay on rank 0), against
# 1 rank's; `partet check` reads the set back on 2 ranks.
"$mpiexec" -n 3 --oversubscribe "$partet" mesh two_spheres.off -k 7 --format msh-parts-binary -o mp_alone --report s.json --quiet &&
  "$partet" mesh two_spheres.off -k 7 --format msh-parts-binary -o mp_one --report a.json --quiet || bad "MSH partitions alone: a run failed"
if [ "$(assembled s.json)/$(assembled a.json)" != False/True ]; then
  bad "MSH partitions alone: assembled on rank 0: $(assembled s.json), on 1 rank $(assembled a.json)"
elif ! out=$(same_partitions mp_alone mp_one); then
  bad "MSH partitions alone: $out"
elif ! "$mpiexec" -n 2 "$partet" check two_spheres.off mp_alone_1.msh > check.log 2>&1; then
  bad "MSH partitions alone: partet check failed: $(tail -n 3 check.log)"
else
  ok "binary MSH partitions alone on 3 ranks: not assembled, 1 rank's set byte for byte ($out), check passed"
fi
# TetGen's files alone (the default), on 3 ranks, with K=7 (some pieces' bulks stay on rank 0, which
# meshes when the others are busy), against 1 rank's files.
"$mpiexec" -n 3 --oversubscribe "$partet" mesh two_spheres.off -k 7 -o t_alone --report s.json --quiet &&
  "$partet" mesh two_spheres.off -k 7 -o t_one --report a.json --quiet || bad "TetGen files alone: a run failed"
if [ "$(assembled s.json)/$(assembled a.json)" != False/True ]; then
  bad "TetGen files alone: assembled on rank 0: $(assembled s.json), on 1 rank $(assembled a.json)"
elif ! err=$(same_files t_alone t_one); then
  bad "TetGen files alone: $err"
elif ! "$mpiexec" -n 2 "$partet" check two_spheres.off t_alone > check.log 2>&1; then
  bad "TetGen files alone: partet check failed: $(tail -n 3 check.log)"
else
  ok "TetGen files alone on 3 ranks: not assembled, 1 rank's files byte for byte ($(head -n 1 t_alone.ele | cut -d' ' -f1) tets), check passed"
fi
# A binary MSH file alone, on 3 ranks, with K=7, against 1 rank's; `partet check` reads it back.
"$mpiexec" -n 3 --oversubscribe "$partet" mesh two_spheres.off -k 7 --format msh-binary -o b_alone --report s.json --quiet &&
  "$partet" mesh two_spheres.off -k 7 --format msh-binary -o b_one --report a.json --quiet || bad "binary MSH alone: a run failed"
if [ "$(assembled s.json)/$(assembled a.json)" != False/True ]; then
  bad "binary MSH alone: assembled on rank 0: $(assembled s.json), on 1 rank $(assembled a.json)"
elif ! err=$(same_files b_alone b_one); then
  bad "binary MSH alone: $err"
elif ! "$partet" check two_spheres.off b_alone.msh > check.log 2>&1; then
  bad "binary MSH alone: partet check failed: $(tail -n 3 check.log)"
else
  ok "binary MSH alone on 3 ranks: not assembled, 1 rank's file byte for byte, check passed"
fi
# Two spread runs at once on one prefix (K=5 and K=7, 2 ranks each): both end well, and what is
# left there is one run's whole set (every single file, .pvtu piece file and MSH partition as that run
# writes them alone, no file of the other, no temporary), which `partet check` passes.
both=(--format tetgen,vtu,medit,pvtu,msh-parts --quiet)
"$mpiexec" -n 2 "$partet" mesh genus3.off -k 5 "${both[@]}" -o r5 && "$mpiexec" -n 2 "$partet" mesh genus3.off -k 7 "${both[@]}" -o r7 ||
  bad "two runs at once: a run alone failed"
mkdir at_once
"$mpiexec" -n 2 "$partet" mesh genus3.off -k 5 "${both[@]}" -o at_once/m & first=$!
"$mpiexec" -n 2 "$partet" mesh genus3.off -k 7 "${both[@]}" -o at_once/m; second=$?
wait $first && [ $second = 0 ] || bad "two runs at once: a run failed"
same_as() {  # K: the files at at_once/m are exactly those run K writes alone (the .pvtu index names its own prefix)
  local f n=1
  cmp -s <(sed "s/\"r$1_/\"X_/" r$1.pvtu) <(sed "s/\"m_/\"X_/" at_once/m.pvtu) || return 1
  for f in r$1.node r$1.ele r$1.face r$1.neigh r$1.vtu r$1.mesh r$1_*.vtu r$1_*.msh; do
    cmp -s $f at_once/m${f#r$1} || return 1
    n=$((n + 1))
  done
  [ $n = $(ls at_once | wc -l) ]
}
if same_as 5 || same_as 7; then
  if "$partet" check genus3.off at_once/m > check.log 2>&1 && "$mpiexec" -n 2 "$partet" check genus3.off at_once/m.pvtu >> check.log 2>&1; then
    ok "two runs at once on one prefix: both ended well, one run's whole set left ($(ls at_once | wc -l) files), check passed"
  else
    bad "two runs at once: partet check failed: $(tail -n 3 check.log)"
  fi
else
  bad "two runs at once on one prefix: the files left are no run's whole set: $(ls at_once | tr '\n' ' ')"
fi
summary
