#!/usr/bin/env bash
# partet check on VTK and MEDIT output: a single .vtu, a .pvtu set (its piece files number their
# points by GlobalPointIds) and a MEDIT .mesh, in one process and on 2 and 3 ranks (each reading
# some of the files), must agree with the check of the TetGen files of the same run (vertices,
# tets, boundary faces, volume, V-E+F-T). Damage must fail it, in one process and on 2 ranks: a
# tet turned inside out, a point moved in one piece file only, a tet missing, a piece file missing
# or without GlobalPointIds, a file cut short, a MEDIT triangle turned over. A prefix with & < " is
# escaped in the .pvtu and .xdmf files, which VTK and meshio then read.
# Usage: check_vtk_medit.sh PARTET MPIEXEC
set -euo pipefail
partet=$1 mpiexec=$2 tests=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
"$partet" generate two_spheres --faces 4000 -o in.off > /dev/null
"$mpiexec" -n 2 "$partet" mesh in.off -o m --pieces 4 --format tetgen,vtu,pvtu,medit --quiet
"$partet" check in.off m --json > serial.json
. "$tests/formats/check_helpers.sh"
for set in m.vtu m.pvtu m.mesh; do
  "$partet" check in.off "$set" --json > "$set.json"
  same_as_tetgen_files "$set.json" "$set"
  for n in 2 3; do
    "$mpiexec" -n $n "$partet" check in.off "$set" --json > "$set.n$n.json"
    same_as_tetgen_files "$set.n$n.json" "$set on $n ranks"
  done
done

# A damaged copy of the run in d/, checked by NAMED (a file of d/) in one process and on 2 ranks.
damaged() {  # NAME NAMED EXPECTED EXPECTED-ON-RANKS
  fails "$1" "$3" "$partet" check in.off "d/$2"
  fails "$1, on 2 ranks" "$4" "$mpiexec" -n 2 "$partet" check in.off "d/$2"
}
fresh() { rm -rf d && mkdir d && cp m.* m_*.vtu d/; }
vtu() { "$tests/formats/vtu_file.py" "$@"; }  # FILE PYTHON (on a: the arrays by name)

fresh && vtu d/m.vtu "c = a['connectivity']; c[0], c[1] = c[1], c[0]"
damaged "a tet turned inside out (.vtu)" m.vtu "tets are not positively oriented" "tets are inverted"
fresh && vtu d/m_p1.vtu "c = a['connectivity']; c[4], c[5] = c[5], c[4]"
damaged "a tet turned inside out (a .pvtu piece)" m.pvtu "tets are not positively oriented" "tets are inverted"
# A point of the seams' file that piece 1's file has too, moved in the seams' file only.
fresh && vtu d/m_seams.vtu "
import vtu_file
other = set(vtu_file.read('d/m_p1.vtu')[0]['GlobalPointIds'])
i = next(i for i, g in enumerate(a['GlobalPointIds']) if g in other)
a['Points'][3 * i] += 1e-3"
damaged "a point moved in one piece file" m.pvtu "other coordinates than an earlier file" \
  "two files of the set of 'd/m.pvtu' give node [0-9]* other coordinates"
fresh && vtu d/m_p0.vtu "
for k in ('connectivity',): a[k] = a[k][4:]
for k in ('offsets',): a[k] = a[k][1:] - 4
for k in ('types', 'piece', 'region'): a[k] = a[k][1:]
head = head.replace('NumberOfCells=\"%d\"' % (len(a['types']) + 1), 'NumberOfCells=\"%d\"' % len(a['types']))"
damaged "a tet missing" m.pvtu "input triangles are not boundary faces" \
  "boundary faces of the mesh are not input triangles"
fresh && rm d/m_p3.vtu
damaged "a missing piece file" m.pvtu "cannot open 'd/m_p3.vtu'" "cannot open 'd/m_p3.vtu'"
fresh && vtu d/m_seams.vtu "del a['GlobalPointIds']"
damaged "a piece file without GlobalPointIds" m.pvtu "has no GlobalPointIds" "has no GlobalPointIds"
fresh && truncate -s -5000 d/m.vtu
damaged "a .vtu cut short" m.vtu "ends early\|does not decompress" "ends early\|does not decompress"
fresh && /usr/bin/python3 -c "
lines = open('d/m.mesh').read().split('\n')
t = lines.index('Triangles') + 2
v = lines[t].split(); v[0], v[1] = v[1], v[0]; lines[t] = ' '.join(v)
open('d/m.mesh', 'w').write('\n'.join(lines))"
damaged "a MEDIT triangle turned over" m.mesh "MEDIT triangles do not list exactly the outward" \
  "triangles of the MEDIT file face into their tet"

# A prefix with XML's special characters: the .pvtu index and the .xdmf file name their files
# escaped, so VTK and meshio read them (before, VTK read no cells) and so does partet check.
"$mpiexec" -n 2 "$partet" mesh in.off -o 'r&d<"x' --pieces 4 --format pvtu,xdmf --quiet
for set in 'r&d<"x.pvtu' 'r&d<"x.xdmf'; do
  "$partet" check in.off "$set" --json > special.json
  same_as_tetgen_files special.json "$set"
done
/usr/bin/python3 -c "
import json, meshio, vtk
tets = json.load(open('serial.json'))['tets']
reader = vtk.vtkXMLPUnstructuredGridReader()
reader.SetFileName('r&d<\"x.pvtu')
reader.Update()
assert reader.GetOutput().GetNumberOfCells() == tets, reader.GetOutput().GetNumberOfCells()
assert len(meshio.read('r&d<\"x.xdmf').cells[0].data) == tets
print('ok: VTK reads the .pvtu and meshio the .xdmf at a prefix with & < \"')"
