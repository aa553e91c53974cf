#!/usr/bin/env bash
# partet check on MSH output: a single .msh file and a partition set (named by any of its files),
# ASCII and binary, in one process and on 2 and 3 ranks (each reading some of the files), must
# agree with the check of the TetGen files of the same run (vertices, tets, boundary faces, volume,
# V-E+F-T), and damage must fail it, in one process and on 2 ranks: a boundary triangle turned
# over, a node moved in one partition file only, a missing partition file.
# Usage: check_msh.sh PARTET MPIEXEC
set -euo pipefail
partet=$1 mpiexec=$2 tests=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
"$partet" generate two_spheres --faces 4000 -o in.off > /dev/null
"$mpiexec" -n 2 "$partet" mesh in.off -o m --pieces 4 --format tetgen,msh,msh-parts --quiet
"$mpiexec" -n 2 "$partet" mesh in.off -o b --pieces 4 --format msh-binary,msh-parts-binary --quiet
"$partet" check in.off m --json > serial.json
. "$tests/formats/check_helpers.sh"
for set in m.msh m_1.msh m_3.msh b.msh b_2.msh; do
  "$partet" check in.off "$set" --json > "$set.json"
  same_as_tetgen_files "$set.json" "$set"
done
for n in 2 3; do
  for set in m.msh m_3.msh b_2.msh; do
    "$mpiexec" -n $n "$partet" check in.off "$set" --json > "$set.n$n.json"
    same_as_tetgen_files "$set.n$n.json" "$set on $n ranks"
  done
done


damage() {  # NAME PYTHON-STATEMENTS (on lines, the text of d_2.msh) EXPECTED-MESSAGE EXPECTED-ON-RANKS
  for i in 1 2 3 4 5; do cp "m_$i.msh" "d_$i.msh"; done
  /usr/bin/python3 -c "
lines = open('d_2.msh').read().split('\n')
$2
open('d_2.msh', 'w').write('\n'.join(lines))"
  fails "$1" "$3" "$partet" check in.off d_1.msh
  fails "$1, on 2 ranks" "$4" "$mpiexec" -n 2 "$partet" check in.off d_1.msh
}
# The first triangle of the first element block: its element tag, then its three node tags.
damage "triangle turned over" "
e = lines.index('\$Elements') + 3
t = lines[e].split(); t[1], t[2] = t[2], t[1]; lines[e] = ' '.join(t)" "MSH triangles do not list exactly the outward" \
  "triangles of the MSH files face into their tet"
# The coordinates of a node that partition 1 has too, in partition 2's file only.
damage "node moved in one file" "
def node_tags(text):
    n = text.index('\$Nodes') + 2
    count = int(text[n].split()[3])
    return n, [int(t) for t in text[n + 1:n + 1 + count]]
_, first = node_tags(open('m_1.msh').read().split('\n'))
n, tags = node_tags(lines)
i = next(i for i, tag in enumerate(tags) if tag in set(first))
row = n + 1 + len(tags) + i
x = lines[row].split(); x[0] = repr(float(x[0]) + 1e-3); lines[row] = ' '.join(x)" \
  "other coordinates than an earlier file" "two files of the set of 'd_1.msh' give node [0-9]* other coordinates"
for i in 1 2 3 4 5; do cp "m_$i.msh" "d_$i.msh"; done
rm d_4.msh
fails "a missing partition file" "cannot open 'd_4.msh'" "$partet" check in.off d_1.msh
fails "a missing partition file, on 2 ranks" "cannot open 'd_4.msh'" "$mpiexec" -n 2 "$partet" check in.off d_1.msh
fails "--report on ranks" "need the whole mesh in one process" "$mpiexec" -n 2 "$partet" check in.off m_1.msh --report r
