#!/usr/bin/env bash
# Only the XDMF set from several ranks: rank 0 does not assemble the mesh; every bulk's rows are
# written by the rank that meshed it (the report says assembled_on_rank0: false). The set must
# hold exactly what the assembled path writes (the same run with TetGen files too, which
# assembles): every dataset equal, and the HDF5 files byte for byte; `partet check` passes on it.
# Shapes with one solid and with two; 2 and 4 ranks.
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
assembled() { /usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["assembled_on_rank0"])' "$1"; }
regions() { /usr/bin/python3 -c 'import h5py,sys; print(int(h5py.File(sys.argv[1],"r")["/Mesh/mesh/region"][()].max()))' "$1"; }
for shape in genus3 two_spheres nested; do
  "$partet" generate $shape --faces 6000 -o $shape.off > /dev/null || exit 1
  for n in 2 4; do
    name="$shape on $n ranks"
    "$mpiexec" -n $n --oversubscribe "$partet" mesh $shape.off -k 6 --format xdmf -o s_${shape}_$n --report s.json --quiet ||
      { bad "$name: the spread run failed"; continue; }
    "$mpiexec" -n $n --oversubscribe "$partet" mesh $shape.off -k 6 --format xdmf,tetgen -o a_${shape}_$n --report a.json --quiet ||
      { bad "$name: the assembled run failed"; continue; }
    [ "$(assembled s.json)/$(assembled a.json)" = False/True ] ||
      { bad "$name: assembled on rank 0: spread run $(assembled s.json), with TetGen files $(assembled a.json)"; continue; }
    if ! out=$(same_sets s_${shape}_$n a_${shape}_$n 2>&1); then bad "$name: the sets differ: $out"; continue; fi
    bytes=same
    cmp -s s_${shape}_$n.h5 a_${shape}_$n.h5 && cmp -s s_${shape}_${n}_boundary.h5 a_${shape}_${n}_boundary.h5 || bytes=different
    [ $bytes = same ] || { bad "$name: the HDF5 files' datasets agree but their bytes differ"; continue; }
    "$mpiexec" -n 2 "$partet" check $shape.off s_${shape}_$n.xdmf > check.log 2>&1 ||
      { bad "$name: partet check failed: $(tail -n 3 check.log)"; continue; }
    ok "$name: written by the owners of its parts, the assembled path's set byte for byte ($(regions s_${shape}_$n.h5) solid(s)), check passed"
  done
done
summary
