#!/usr/bin/env bash
# scripts/render.py draws a PNG of a meshed generated surface, cut open and coloured by piece.
# Usage: render.sh PARTET
set -euo pipefail
partet=$(realpath "$1")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$partet" generate genus3 --faces 4000 -o "$work/g.off" > /dev/null
"$partet" mesh "$work/g.off" -o "$work/g" --pieces 4 --format vtu --quiet
"$(dirname "$0")/../../scripts/render.py" "$work/g.vtu" "$work/g.png"
/usr/bin/python3 - "$work/g.png" <<'PY'
import sys
import matplotlib.image as image
import numpy as np
png = image.imread(sys.argv[1])
colours = len(np.unique((png[..., :3] * 255).astype(int).reshape(-1, 3), axis=0))
assert png.shape[0] > 400 and png.shape[1] > 400, png.shape
assert colours > 50, f"only {colours} colours: an empty picture?"
print(f"ok: {png.shape[1]}x{png.shape[0]} picture, {colours} colours")
PY
