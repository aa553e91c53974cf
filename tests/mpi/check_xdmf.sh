#!/usr/bin/env bash
# partet check on an XDMF set, each rank checking its part: on 1, 2 and 3 ranks it must agree with
# the serial check of the TetGen files of the same run (vertices, tets, boundary faces, volume,
# V-E+F-T), and it must catch each kind of damage, done to the HDF5 files with h5py: an inverted
# tet, a boundary triangle turned over, a moved vertex, a tet pointing at a vertex out of range,
# and a different input.
# Usage: check_xdmf.sh PARTET MPIEXEC
set -euo pipefail
partet=$1 mpiexec=$2 tests=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
"$partet" generate two_spheres --faces 4000 -o in.off > /dev/null
"$partet" generate genus3 --faces 4000 -o other.off > /dev/null
"$mpiexec" -n 2 "$partet" mesh in.off -o m --pieces 4 --format tetgen,xdmf --quiet
"$partet" check in.off m --json > serial.json
for n in 1 2 3; do
  "$mpiexec" -n $n "$partet" check in.off m.xdmf --json > n$n.json
  "$tests/same_check.py" serial.json n$n.json "$n ranks" "the serial check"
done

damage() {  # NAME PYTHON-STATEMENTS EXPECTED-VIOLATION
  cp m.h5 d.h5 && cp m_boundary.h5 d_boundary.h5 && cp m.xdmf d.xdmf
  /usr/bin/python3 -c "
import h5py
with h5py.File('d.h5', 'r+') as mesh, h5py.File('d_boundary.h5', 'r+') as boundary:
    tets, points, faces = mesh['Mesh/mesh/topology'], mesh['Mesh/mesh/geometry'], boundary['MeshTags/boundary/topology']
    $2"
  if "$mpiexec" -n 2 "$partet" check in.off d.xdmf > out; then echo "FAIL: $1 passed the check"; cat out; exit 1; fi
  grep -q "$3" out || { echo "FAIL: $1: no violation '$3':"; cat out; exit 1; }
  echo "ok: $1: $(grep VIOLATION out | head -n 2 | tr '\n' ' ')"
}
damage "inverted tet" "t = tets[7]; t[[0, 1]] = t[[1, 0]]; tets[7] = t" "tets are inverted"
damage "boundary turned over" "f = faces[3]; f[[0, 1]] = f[[1, 0]]; faces[3] = f" "face into their tet"
damage "moved vertex" "i = int(faces[0][0]); p = points[i]; p[0] += 1e-6; points[i] = p" "input triangles are not boundary faces"
damage "id out of range" "t = tets[0]; t[2] = len(points) + 5; tets[0] = t" "out of range"
if "$mpiexec" -n 2 "$partet" check other.off m.xdmf > out; then echo "FAIL: another input passed"; exit 1; fi
grep -q "not input triangles" out && echo "ok: another input: $(grep VIOLATION out | head -n 1)"
