#!/usr/bin/env bash
# Every output format round-trips through independent readers (tests/formats/round_trip.py):
# a generated surface meshed on 2 ranks into all formats at once, then checked against the
# TetGen files of the same run (and the XDMF set read by DOLFINx in parallel). Two shapes: one
# solid (genus 3) and two disjoint solids.
# Usage: formats.sh PARTET MPIEXEC
set -euo pipefail
partet=$1 mpiexec=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
here=$(dirname "$0")
for case in "genus3 1" "two_spheres 2"; do
  read -r shape regions <<< "$case"
  "$partet" generate "$shape" --faces 4000 -o "$work/$shape.off" > /dev/null
  "$mpiexec" -n 2 "$partet" mesh "$work/$shape.off" -o "$work/$shape" --pieces 4 --quiet \
    --format tetgen,vtu,pvtu,msh,msh-parts,medit,xdmf
  # -o with an extension chooses the format.
  "$mpiexec" -n 2 "$partet" mesh "$work/$shape.off" -o "$work/${shape}_binary.msh" --pieces 4 --quiet \
    --format msh-binary,msh-parts-binary
  "$partet" check "$work/$shape.off" "$work/$shape" | tail -n 1
  /usr/bin/python3 "$here/round_trip.py" "$work/$shape" 4 "$regions"
  # The MSH partitions (one per piece file of the .pvtu set), read by gmsh against the single .msh.
  parts=$(ls "$work/$shape"_p[0-9]*.vtu "$work/${shape}_seams.vtu" 2> /dev/null | wc -l)
  /usr/bin/python3 "$here/msh_parts.py" "$work/$shape.msh" "$parts" "$work/$shape" "$work/${shape}_binary" 2>&1 |
    grep -v "tag data that couldn't be processed" | grep .
  # DOLFINx reads the XDMF set in parallel, as a FEM code would.
  "$mpiexec" -n 2 /usr/bin/python3 "$here/dolfinx_read.py" "$work/$shape" 2>&1 | grep -v "^INFO:"
  # The HDF5 file is written by every rank at once, each its own block: on 1 and 4 ranks (and
  # with -o NAME.xdmf choosing the format) the set is the same, byte for byte.
  for n in 1 4; do
    "$mpiexec" -n $n "$partet" mesh "$work/$shape.off" -o "$work/${shape}_n$n.xdmf" --pieces 4 --quiet
    cmp "$work/$shape.h5" "$work/${shape}_n$n.h5"
    cmp "$work/${shape}_boundary.h5" "$work/${shape}_n${n}_boundary.h5"
    sed "s/${shape}_n$n/$shape/" "$work/${shape}_n$n.xdmf" | cmp - "$work/$shape.xdmf"
    sed "s/${shape}_n$n/$shape/g" "$work/${shape}_n${n}_boundary.xdmf" | cmp - "$work/${shape}_boundary.xdmf"
  done
  echo "ok: the XDMF set of 2 ranks is byte-identical to that of 1 and 4 ranks"
  # The piece files of the .pvtu set and the MSH partitions are written by whichever rank is
  # free: on 1 and 4 ranks the sets are the same, byte for byte, and on 4 every rank but 0 wrote
  # at least one of the 10 files (each is sent one at once; rank 0 may be left none).
  for n in 1 4; do
    "$mpiexec" -n $n "$partet" mesh "$work/$shape.off" -o "$work/${shape}_n$n.pvtu" --pieces 4 --quiet \
      --format msh-parts --report "$work/report_n$n.json"
    for part in seams p0 p1 p2 p3; do cmp "$work/${shape}_$part.vtu" "$work/${shape}_n${n}_$part.vtu"; done
    sed "s/${shape}_n${n}_/${shape}_/" "$work/${shape}_n$n.pvtu" | cmp - "$work/$shape.pvtu"
    for part in 1 2 3 4 5; do cmp "$work/${shape}_$part.msh" "$work/${shape}_n${n}_$part.msh"; done
  done
  /usr/bin/python3 -c "
import json, sys
n4, n1 = ([r['piece_files_written'] for r in json.load(open(path))['rank']] for path in sys.argv[1:])
assert sum(n4) == 10 and min(n4[1:]) >= 1 and n1 == [10], (n4, n1)" "$work/report_n4.json" "$work/report_n1.json"
  echo "ok: the .pvtu set and the MSH partitions of 2 ranks are byte-identical to those of 1 and 4 ranks (piece files written per rank on 4: $(/usr/bin/python3 -c "import json, sys; print([int(r['piece_files_written']) for r in json.load(open(sys.argv[1]))['rank']])" "$work/report_n4.json"))"
done

# A publish that fails midway (the 7th of 22 moves) keeps the whole previous set, the per-piece
# .vtu files included, and leaves no temporaries.
cd "$work"
mkdir before
cp genus3.node genus3.ele genus3.face genus3.neigh genus3.vtu genus3.pvtu genus3_p*.vtu genus3_seams.vtu genus3.msh \
  genus3_[1-5].msh genus3.mesh genus3.xdmf genus3_boundary.xdmf genus3.h5 genus3_boundary.h5 before/
if PARTET_INJECT_PUBLISH_FAILURE=7 "$partet" mesh two_spheres.off -o genus3 --pieces 4 --quiet \
  --format tetgen,vtu,pvtu,msh,msh-parts,medit,xdmf 2> log; then
  echo "FAIL: the injected publish failure exited 0"; exit 1
fi
for f in before/*; do
  cmp -s "$f" "$(basename "$f")" || { echo "FAIL: $(basename "$f") changed by a failed run"; cat log; exit 1; }
done
if ls | grep -q '\.tmp-'; then echo "FAIL: temporaries left: $(ls | grep '\.tmp-')"; exit 1; fi
echo "ok: a failed publish kept all $(ls before | wc -l) files of the previous set"
