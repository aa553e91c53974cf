#!/usr/bin/env bash
# What makes a piece expensive? Meshes INPUT in K pieces on one rank (pieces one after another,
# so each piece's time is TetGen's alone), dumps the pieces, and prints per piece its triangles,
# cap triangles, enclosed volume, TetGen seconds and tets, then how well triangles and volume
# predict the time (correlation) and the spread (slowest / fastest, slowest / mean).
# Time it on a quiet machine.
#
# Usage: piece_cost.sh INPUT K [partet mesh options...]
set -euo pipefail
source "$(dirname "$0")/common.sh"
[ $# -ge 2 ] || { sed -n '2,8p' "$0"; exit 2; }
input=$1 k=$2
shift 2
make_work_dir
mkdir -p "$work/pieces"
"$partet" mesh "$input" -o "$work/out" --pieces "$k" --dump-pieces "$work/pieces" --report "$work/r.json" --quiet "$@"
for f in "$work"/pieces/piece_*.off; do "$partet" info "$f" --json > "${f%.off}.json"; done
/usr/bin/python3 - "$work" <<'PY'
import glob, json, sys
import numpy as np
work = sys.argv[1]
report = json.load(open(f"{work}/r.json"))
rows = []
for p in report["piece"]:
    info = json.load(open(f"{work}/pieces/piece_{p['index']}.json"))
    rows.append((p["index"], p["triangles"], info["volume"], p["tetgen_seconds"]))
rows.sort()
print(f"{'piece':>5} {'triangles':>10} {'volume':>12} {'seconds':>8}")
for i, t, v, s in rows:
    print(f"{i:>5} {t:>10} {v:>12.5g} {s:>8.2f}")
t, v, s = (np.array([r[c] for r in rows], dtype=float) for c in (1, 2, 3))
corr = lambda a, b: float(np.corrcoef(a, b)[0, 1]) if len(a) > 2 else float("nan")
print(f"correlation of time with triangles {corr(t, s):.2f}, with volume {corr(v, s):.2f}")
print(f"spread: slowest / fastest {s.max() / s.min():.2f}, slowest / mean {s.max() / s.mean():.2f}; "
      f"triangles max / min {t.max() / t.min():.2f}")
PY
