#!/usr/bin/env bash
# Every bad input or option gets a one-line error saying what is wrong and where, a non-zero
# exit code within 10 s, and no output file. Usage: bad_input.sh PARTET [MESHES_DIR] [LAUNCH...]
# (LAUNCH, e.g. "mpiexec -n 2", runs partet mesh under MPI.)
set -uo pipefail
partet=$(realpath "$1") meshes=${2:-}
[ -n "$meshes" ] && [ -d "$meshes" ] && meshes=$(realpath "$meshes")
shift 2 2>/dev/null || shift $#
launch=("$@")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
printf 'OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n' > truncated.off
printf 'OFF\n0 0 0\n' > empty.off
printf 'OFF\n4 4 0\n0 0 0\n1 0 0\nnan 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' > nan.off
printf 'OFF\n4 4 0\n0 0 0\n1 0 0\ninf 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' > inf.off
printf 'OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 7\n' > range.off
printf 'OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n' > open.off
printf 'OFF\n4 2 0\n0 0 0\n1 1 0\n1 0 0\n0 1 0\n4 0 1 2 3\n4 0 3 2 1\n' > bowtie.off
printf 'OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 3 1\n3 0 2 3\n3 1 3 2\n' > inside_out.off
printf 'OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' > tet.off
echo "not a mesh" > model.xyz
mkfifo fifo.off
ln -s /dev/urandom random.stl
head -c 3000 /dev/urandom > noise.stl
printf '\xef\xbb\xbfsolid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid x\n' > bom.stl

# Unused vertex far away, and a thin solid: valid inputs that must mesh.
printf 'OFF\n5 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1e12 1e12 1e12\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' > far_unused.off
printf 'OFF\n8 12 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1e-9\n1 0 1e-9\n1 1 1e-9\n0 1 1e-9\n3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n3 1 2 6\n3 1 6 5\n3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n' > thin.off
printf 'solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n' > cut.stl
# A byte order mark (as Windows editors write) before valid content: read past it.
{ printf '\xef\xbb\xbf'; cat tet.off; } > bom_tet.off
# Hostile surroundings: a FIFO or a directory where a mesh file should be; links as outputs.
mkfifo fifo_mesh.node && cp tet.off fifo_mesh.ele
mkdir dir_mesh.node
ln -s elsewhere.node linked.node
long=$(printf 'n%.0s' $(seq 230))
printf '{"cut_planes": [{"normal": [1, 0], "offset": 0}]}' > short_normal.json

pass=0 fail=0
# expect CODE REGEX -- ARGS...: CODE is "fail" (non-zero exit), "usage" (exit code 2) or "ok".
expect() {
  local want=$1 regex=$2
  shift 3
  rm -f out.*
  local start=$SECONDS
  [ "$1" = mesh ] && set -- "${launch[@]}" "$partet" "$@"
  timeout 10 "$@" > log 2>&1
  local code=$? elapsed=$((SECONDS - start))
  local problem=""
  if [ "$want" = usage ]; then
    [ "$code" -eq 2 ] || problem="exit code $code, not 2"
    # One line (under a launcher, one from partet: the launcher adds its own).
    if [ ${#launch[@]} -eq 0 ]; then [ "$(wc -l < log)" -eq 1 ] || problem="${problem:+$problem; }not one line"
    else [ "$(grep -c '^partet' log)" -eq 1 ] || problem="${problem:+$problem; }not one partet line"; fi
    grep -q "^partet: error: " log || problem="${problem:+$problem; }no 'partet: error:' prefix"
  elif [ "$want" = fail ]; then
    [ "$code" -ne 0 ] || problem="exit code 0"
    [ "$code" -ne 124 ] || problem="did not end within 10 s"
    ls out.* > /dev/null 2>&1 && problem="output files left: $(ls out.*)"
  else
    [ "$code" -eq 0 ] || problem="exit code $code"
  fi
  grep -Eq -- "$regex" log || problem="${problem:+$problem; }message does not match /$regex/"
  if [ -z "$problem" ]; then
    pass=$((pass + 1)); echo "ok   ($elapsed s) ${*#$partet }: $(grep -Em1 -- "$regex" log)"
  else
    fail=$((fail + 1)); echo "FAIL $*: $problem"; sed 's/^/     | /' log | head -5
  fi
}

expect usage "cannot open 'missing.off': no such file" -- mesh missing.off -o out
expect usage "unknown format '.xyz'" -- mesh model.xyz -o out
expect fail "ends after 2 of 4 faces" -- mesh truncated.off -o out
expect fail "not a valid STL|truncated" -- mesh cut.stl -o out
expect fail "contains no faces" -- mesh empty.off -o out
expect fail "vertex 2 has a non-finite coordinate \(nan\)" -- mesh nan.off -o out
expect fail "vertex 2 has a non-finite coordinate \(inf\)" -- mesh inf.off -o out
expect fail "face 3 refers to vertex 7" -- mesh range.off -o out
expect fail "face 0 has 4 corners and cannot be triangulated" -- mesh bowtie.off -o out
expect fail "input is not closed: 3 border edges" -- mesh open.off -o out
expect fail "inside out" -- mesh inside_out.off -o out
expect usage "--pieces: Value 0 not in range" -- mesh tet.off -o out --pieces 0
expect usage "--density" -- mesh tet.off -o out --density -1
for q in abc 0.5 inf nan 1e-300 0x1p1 -2 1.5/30 1.5/-1 "1.4 2"; do
  expect usage "--quality: the quality bound must be R or R/ANGLE" -- mesh tet.off -o out --quality "$q"
done
expect usage "--axis: diagonal not in" -- mesh tet.off -o out --axis diagonal
expect usage "--density: the value must be a finite number, not nan" -- mesh tet.off -o out -d nan
expect usage "--piece-timeout: the value must be a finite number, not inf" -- mesh tet.off -o out --piece-timeout inf
expect usage "--dump-pieces: directory 'nodir' does not exist" -- mesh tet.off -o out --dump-pieces nodir
expect usage "--format: msh and msh-binary both write PREFIX.msh" -- mesh tet.off -o out --format msh,msh-binary
expect usage "cannot write 'linked.node': it is a symbolic link" -- mesh tet.off -o linked
expect usage "its name is too long for the filesystem once partet's temporary suffix is added" -- mesh tet.off -o "$long"
"$partet" generate sphere --faces 20000 -o sphere.off > /dev/null
expect usage "cannot subdivide [0-9]+ faces x 4\^8 = .* faces: that needs about .* GB of memory" -- \
  "$partet" refine-surface sphere.off -o out.off --loop 8
expect usage "input is required" -- mesh
expect usage "subcommand" -- "$partet" frobnicate
expect usage "cannot read 'fifo.off': not a regular file" -- mesh fifo.off -o out
expect fail "cannot read fifo_mesh.node: not a regular file" -- "$partet" check tet.off fifo_mesh
expect fail "cannot read fifo_mesh.node: not a regular file" -- "$partet" info fifo_mesh.node
expect fail "cannot read dir_mesh.node: it is a directory" -- "$partet" info dir_mesh.node
expect fail "report 'short_normal.json': cut_planes\[0\].normal must be a list of 3 numbers" -- \
  "$partet" check tet.off out --report short_normal.json
expect usage "cannot read 'random.stl': not a regular file" -- mesh random.stl -o out
expect fail "cannot read 'noise.stl': not an STL file" -- mesh noise.stl -o out
expect fail "input is not closed" -- mesh bom.stl -o out
expect ok "wrote out.node" -- mesh bom_tet.off -o out
expect usage "the output prefix 'out/' names no file" -- mesh tet.off -o out/
expect usage "the output prefix '' names no file" -- mesh tet.off -o ""
expect usage "cannot write 'nodir/out.node': directory 'nodir' does not exist" -- mesh tet.off -o nodir/out
expect usage "cannot write 'out.node': it is the same file as 'out.node'" -- mesh tet.off -o out --report out.node
expect usage "cannot write 'tet.off': it is the same file as 'tet.off'" -- mesh tet.off -o out --report tet.off
expect ok "wrote out.node" -- mesh far_unused.off -o out --check
expect ok "wrote out.node" -- mesh thin.off -o out --pieces 2 --check
expect ok "using [0-9]+ pieces instead of 50" -- mesh tet.off -o out --pieces 50
if [ ${#launch[@]} -eq 0 ]; then
  # MPI's session directory under a TMPDIR that cannot be written (under a file; on a read-only
  # filesystem where this test may mount one): one line, not a page of Open MPI errors. A missing
  # one is made.
  expect usage "TMPDIR=.*/tet.off/tmp is not a writable directory" -- env TMPDIR="$work/tet.off/tmp" "$partet" mesh tet.off -o out
  expect ok "wrote out.node" -- env TMPDIR="$work/missing/tmp" "$partet" mesh tet.off -o out
  if mkdir ro_tmp && mount -t tmpfs -o ro tmpfs ro_tmp 2> /dev/null; then
    expect usage "TMPDIR=.*/ro_tmp is not a writable directory" -- env TMPDIR="$work/ro_tmp" "$partet" mesh tet.off -o out
    umount ro_tmp
  fi
fi
if [ -n "$meshes" ] && [ -d "$meshes/invalid" ]; then
  expect fail "input is not closed: 223 border edges" -- mesh "$meshes/invalid/bunny_open.off" -o out
  expect fail "input is not manifold: vertex 253 joins 2 separate fans" -- mesh "$meshes/invalid/cow_nonmanifold_vertex.off" -o out
  expect fail "input self-intersects: faces [0-9]+ and [0-9]+ intersect \(37 intersecting pairs\)" -- \
    mesh "$meshes/invalid/neptune_selfintersecting.off" -o out --pieces 2
fi
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
