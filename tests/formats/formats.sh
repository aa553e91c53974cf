#!/usr/bin/env bash
# Every output format round-trips through independent readers (tests/formats/round_trip.py):
# a generated surface meshed on 2 ranks into all formats at once, then checked against the
# TetGen files of the same run. Two shapes: one solid (genus 3) and two disjoint solids.
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
    --format tetgen,vtu,pvtu,msh,medit
  # -o with an extension chooses the format.
  "$mpiexec" -n 2 "$partet" mesh "$work/$shape.off" -o "$work/${shape}_binary.msh" --pieces 4 --quiet \
    --format msh-binary
  "$partet" check "$work/$shape.off" "$work/$shape" | tail -n 1
  /usr/bin/python3 "$here/round_trip.py" "$work/$shape" 4 "$regions"
done

# A publish that fails midway (the 7th of 13 moves) keeps the whole previous set, the per-piece
# .vtu files included, and leaves no temporaries.
cd "$work"
mkdir before
cp genus3.node genus3.ele genus3.face genus3.neigh genus3.vtu genus3.pvtu genus3_p*.vtu genus3_seams.vtu genus3.msh \
  genus3.mesh before/
if PARTET_INJECT_PUBLISH_FAILURE=7 "$partet" mesh two_spheres.off -o genus3 --pieces 4 --quiet \
  --format tetgen,vtu,pvtu,msh,medit 2> log; then
  echo "FAIL: the injected publish failure exited 0"; exit 1
fi
for f in before/*; do
  cmp -s "$f" "$(basename "$f")" || { echo "FAIL: $(basename "$f") changed by a failed run"; cat log; exit 1; }
done
if ls | grep -q '\.tmp-'; then echo "FAIL: temporaries left: $(ls | grep '\.tmp-')"; exit 1; fi
echo "ok: a failed publish kept all $(ls before | wc -l) files of the previous set"
