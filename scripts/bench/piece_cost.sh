#!/usr/bin/env bash
# What makes a piece expensive, and how even the planes make the pieces. Meshes INPUT in K pieces
# on one rank (pieces one after another, so each piece's time is TetGen's alone), once with the
# planes balancing vertex counts and once balancing the estimated cost, RUNS times each,
# alternating. Prints per piece its triangles, estimated cost, tets and median TetGen seconds,
# then per balance the spread (slowest piece over the mean, of the medians) and how well the
# estimate predicts the time (correlation). Time it on a quiet machine.
#
# Usage: piece_cost.sh [-r RUNS] INPUT K [partet mesh options...]
set -euo pipefail
source "$(dirname "$0")/../common.sh"
runs=3
while getopts "r:" opt; do
  case $opt in r) runs=$OPTARG ;; *) sed -n '2,9p' "$0"; exit 2 ;; esac
done
shift $((OPTIND - 1))
[ $# -ge 2 ] || { sed -n '2,9p' "$0"; exit 2; }
input=$1 k=$2
shift 2
make_work_dir
for r in $(seq "$runs"); do
  for balance in vertices cost; do
    "$partet" mesh "$input" -o "$work/out" --pieces "$k" --balance "$balance" --report "$work/$balance.$r.json" \
      --quiet "$@"
  done
done
/usr/bin/python3 - "$work" "$runs" <<'PY'
import json, statistics, sys
import numpy as np
work, runs = sys.argv[1], int(sys.argv[2])
for balance in ("vertices", "cost"):
    reports = [json.load(open(f"{work}/{balance}.{r}.json")) for r in range(1, runs + 1)]
    pieces = sorted(reports[0]["piece"], key=lambda p: p["index"])
    seconds = [statistics.median(next(p["tetgen_seconds"] for p in rep["piece"] if p["index"] == q["index"])
                                 for rep in reports) for q in pieces]
    print(f"balance {balance}: {len(pieces)} pieces, median of {runs} runs")
    print(f"{'piece':>5} {'triangles':>10} {'estimate':>10} {'tets':>10} {'seconds':>8}")
    for q, s in zip(pieces, seconds):
        print(f"{q['index']:>5} {q['triangles']:>10} {q['estimated_cost']:>10.0f} {q['tets']:>10} {s:>8.2f}")
    t = np.array([q["triangles"] for q in pieces], float)
    e = np.array([q["estimated_cost"] for q in pieces], float)
    s = np.array(seconds)
    corr = lambda a, b: float(np.corrcoef(a, b)[0, 1]) if len(a) > 2 else float("nan")
    print(f"  spread: slowest / mean {s.max() / s.mean():.3f}, slowest / fastest {s.max() / s.min():.3f}; "
          f"triangles max / mean {t.max() / t.mean():.3f}; estimate max / mean {e.max() / e.mean():.3f}")
    print(f"  correlation of time with triangles {corr(t, s):.2f}, with the estimate {corr(e, s):.2f}")
PY
