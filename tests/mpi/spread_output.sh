#!/usr/bin/env bash
# Only the XDMF set and a .pvtu set from several ranks: rank 0 does not assemble the mesh; every
# bulk's rows and piece file are written by the rank that meshed it (the report says
# assembled_on_rank0: false). The sets must hold exactly what the assembled path writes (the same
# run with TetGen files too, which assembles): every dataset equal, the HDF5 files and every
# piece file byte for byte, the .pvtu index naming the same files; `partet check` passes on both.
# Shapes with one solid and with two; 2 and 4 ranks; and a .pvtu set alone.
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
same_piece_files() {  # A B: the .pvtu sets A.pvtu and B.pvtu name the same piece files, byte for byte
  local a=$1 b=$2 files=0
  cmp -s <(sed "s/\"${a}_/\"X_/" $a.pvtu) <(sed "s/\"${b}_/\"X_/" $b.pvtu) || { echo "the .pvtu indexes differ"; return 1; }
  for f in ${a}_*.vtu; do
    cmp -s $f ${b}_${f#${a}_} || { echo "$f differs from ${b}_${f#${a}_}"; return 1; }
    files=$((files + 1))
  done
  [ $files -gt 0 ] && [ $files = $(ls ${b}_*.vtu | wc -l) ] || { echo "$files piece files, against $(ls ${b}_*.vtu | wc -l)"; return 1; }
  echo "$files piece files"
}
assembled() { /usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["assembled_on_rank0"])' "$1"; }
regions() { /usr/bin/python3 -c 'import h5py,sys; print(int(h5py.File(sys.argv[1],"r")["/Mesh/mesh/region"][()].max()))' "$1"; }
for shape in genus3 two_spheres nested; do
  "$partet" generate $shape --faces 6000 -o $shape.off > /dev/null || exit 1
  for n in 2 4; do
    name="$shape on $n ranks"
    "$mpiexec" -n $n --oversubscribe "$partet" mesh $shape.off -k 6 --format xdmf,pvtu -o s_${shape}_$n --report s.json --quiet ||
      { bad "$name: the spread run failed"; continue; }
    "$mpiexec" -n $n --oversubscribe "$partet" mesh $shape.off -k 6 --format xdmf,pvtu,tetgen -o a_${shape}_$n --report a.json --quiet ||
      { bad "$name: the assembled run failed"; continue; }
    [ "$(assembled s.json)/$(assembled a.json)" = False/True ] ||
      { bad "$name: assembled on rank 0: spread run $(assembled s.json), with TetGen files $(assembled a.json)"; continue; }
    if ! out=$(same_sets s_${shape}_$n a_${shape}_$n 2>&1); then bad "$name: the sets differ: $out"; continue; fi
    bytes=same
    cmp -s s_${shape}_$n.h5 a_${shape}_$n.h5 && cmp -s s_${shape}_${n}_boundary.h5 a_${shape}_${n}_boundary.h5 || bytes=different
    [ $bytes = same ] || { bad "$name: the HDF5 files' datasets agree but their bytes differ"; continue; }
    if ! out=$(same_piece_files s_${shape}_$n a_${shape}_$n); then bad "$name: $out"; continue; fi
    for set in s_${shape}_$n.xdmf s_${shape}_$n.pvtu; do
      "$mpiexec" -n 2 "$partet" check $shape.off $set > check.log 2>&1 || { bad "$name: partet check $set failed: $(tail -n 3 check.log)"; continue 2; }
    done
    ok "$name: written by the owners of its parts, the assembled path's sets byte for byte ($(regions s_${shape}_$n.h5) solid(s), $out), checks passed"
  done
done
# A .pvtu set alone, on 3 ranks, against the same set written with TetGen files (assembled).
"$mpiexec" -n 3 --oversubscribe "$partet" mesh genus3.off -k 5 --format pvtu -o p_alone --report s.json --quiet &&
  "$mpiexec" -n 3 --oversubscribe "$partet" mesh genus3.off -k 5 --format pvtu,tetgen -o a_alone --report a.json --quiet ||
  bad "pvtu alone: a run failed"
if [ "$(assembled s.json)/$(assembled a.json)" != False/True ]; then
  bad "pvtu alone: assembled on rank 0: $(assembled s.json), with TetGen files $(assembled a.json)"
elif ! out=$(same_piece_files p_alone a_alone); then
  bad "pvtu alone: $out"
else
  ok "pvtu alone on 3 ranks: not assembled, the assembled path's set byte for byte ($out)"
fi
summary
