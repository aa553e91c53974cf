#!/usr/bin/env bash
# partet info: the genus, shells and checks of generated surfaces with known answers, an open
# surface and a self-intersecting one, and a tet mesh whose volume must equal its surface's.
# Usage: info.sh PARTET
set -euo pipefail
partet=$(realpath "$1")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
field() { /usr/bin/python3 -c "import json,sys; print(json.load(open('$1'))$2)"; }
for case in "torus 1 1" "genus3 3 1" "nested 0 3" "two_spheres 0 2"; do  # nested: shell, cavity, island
  read -r shape genus shells <<< "$case"
  "$partet" generate "$shape" --faces 3000 -o "$shape.off" > /dev/null
  "$partet" info "$shape.off" --json > "$shape.json"
  [ "$(field "$shape.json" '["genus"]')" = "$genus" ] || fail "$shape: genus $(field "$shape.json" '["genus"]'), expected $genus"
  [ "$(field "$shape.json" '["shells"]')" = "$shells" ] || fail "$shape: shells"
  [ "$(field "$shape.json" '["meshable"]')" = "True" ] || fail "$shape: not meshable"
  echo "ok: $shape genus $genus, $shells shell(s), meshable"
done
# Open: the torus without its last face.
/usr/bin/python3 - torus.off open.off <<'PY'
import sys
lines = open(sys.argv[1]).read().split("\n")
head = lines[1].split(); v, f = int(head[0]), int(head[1])
lines[1] = f"{v} {f - 1} 0"
del lines[2 + v + f - 1]
open(sys.argv[2], "w").write("\n".join(lines))
PY
"$partet" info open.off --json > open.json
[ "$(field open.json '["border_edges"]')" = 3 ] || fail "open: border edges $(field open.json '["border_edges"]')"
[ "$(field open.json '["genus"]')" = -1 ] && [ "$(field open.json '["meshable"]')" = False ] || fail "open: genus or meshable"
echo "ok: open surface: 3 border edges, genus unknown, not meshable"

# Self-intersecting: two overlapping tetrahedra.
cat > crossing.off <<'END'
OFF
8 8 0
0 0 0
1 0 0
0 1 0
0 0 1
0.2 0.2 0.2
1.2 0.2 0.2
0.2 1.2 0.2
0.2 0.2 1.2
3 0 2 1
3 0 1 3
3 0 3 2
3 1 2 3
3 4 6 5
3 4 5 7
3 4 7 6
3 5 6 7
END
"$partet" info crossing.off > crossing.txt
grep -q "self-intersections: .*intersect" crossing.txt || { cat crossing.txt; fail "crossing: no self-intersection reported"; }
grep -q "meshable by partet: no" crossing.txt || fail "crossing: called meshable"
echo "ok: $(grep self-intersections crossing.txt)"
# A tet mesh: its volume is the surface's enclosed volume; its boundary faces the input's.
"$partet" mesh genus3.off -o m --pieces 3 --quiet
"$partet" info m.node --json > m.json
[ "$(field m.json '["boundary_faces"]')" = "$(field genus3.json '["faces"]')" ] || fail "mesh: boundary faces"
[ "$(field m.json '["inverted_tets"]')" = 0 ] && [ "$(field m.json '["solids"]')" = 1 ] || fail "mesh: inverted or solids"
/usr/bin/python3 -c "import json; a=json.load(open('m.json'))['volume']; b=json.load(open('genus3.json'))['volume']; assert abs(a-b) <= 1e-12*abs(b), (a,b)" \
  || fail "mesh: volume differs from the surface's"
"$partet" info m | head -n 1
echo "ok: tet mesh volume equals the surface's, boundary faces equal the input faces"
# Every other format partet writes describes the same mesh as the TetGen files (a set named by any
# of its files: the .pvtu index, an MSH partition).
"$partet" mesh genus3.off -o all --pieces 3 --format tetgen,vtu,pvtu,msh,medit,xdmf --quiet
"$partet" mesh genus3.off -o parts --pieces 3 --format msh-parts-binary --quiet
"$partet" info all --json > all.json
for file in all.vtu all.pvtu all.msh parts_2.msh all.mesh all.xdmf; do
  "$partet" info "$file" --json > other.json || fail "info $file"
  /usr/bin/python3 - all.json other.json <<'PY' || fail "info $file describes another mesh than the TetGen files"
import json, sys
a, b = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
for key in ("vertices", "tets", "boundary_faces", "solids", "inverted_tets"):
    assert a[key] == b[key], (key, a[key], b[key])
assert abs(a["volume"] - b["volume"]) <= 1e-12 * abs(a["volume"]), (a["volume"], b["volume"])
PY
done
echo "ok: info on .vtu, .pvtu, .msh, an MSH partition, .mesh and .xdmf: the TetGen files' mesh"
# A publish killed just after its journal was written: info on the set's file completes it first.
{ PARTET_TEST_PUBLISH_SIGNAL="0:9" "$partet" mesh genus3.off -o killed --pieces 3 --format vtu --quiet > log 2>&1; } 2> /dev/null ||
  true
[ ! -e killed.vtu ] || fail "killed publish: killed.vtu already in place"
"$partet" info killed.vtu > killed.txt 2>&1 || { cat killed.txt; fail "info on a killed publish's file"; }
grep -q "completed the publish" killed.txt && grep -q "^tet mesh killed.vtu: " killed.txt ||
  { cat killed.txt; fail "info did not complete the killed publish"; }
echo "ok: info killed.vtu after a publish killed at its journal: completed, then described"
# --compare-tetgen: with one piece partet is TetGen alone, so the tet counts must agree exactly.
"$partet" mesh genus3.off -o one --pieces 1 --compare-tetgen > compare.txt
grep -q "TetGen alone" compare.txt || { cat compare.txt; fail "no comparison printed"; }
grep -E "^partet:   tets +[0-9]+ +[0-9]+ +1.0000$" compare.txt > /dev/null || { cat compare.txt; fail "1 piece: tets differ from TetGen alone"; }
echo "ok: --compare-tetgen: $(grep -E '^partet:   tets' compare.txt | tr -s ' ')"
