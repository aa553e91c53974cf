#!/usr/bin/env bash
# The README's first command: install, build, then mesh a generated genus-3 surface in 2 pieces
# on 2 MPI ranks with a quality bound (the mesh a simulation would use), verify the result and
# draw it (out/genus3.png).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
source scripts/common.sh
mkdir -p out
./build/partet generate genus3 --faces 20000 -o out/genus3.off
mpirun -np 2 --oversubscribe ./build/partet mesh out/genus3.off -o out/genus3 --pieces 2 --quality 1.414 --format tetgen,vtu
./build/partet check out/genus3.off out/genus3
# A picture of the result, cut open, coloured by piece (open out/genus3.vtu in ParaView for more).
scripts/render.py out/genus3.vtu out/genus3.png
