#!/usr/bin/env bash
# The thin-wall family (partet generate fins|comb|slots|plates) at several wall/gap ratios and
# turns, each meshed at several piece counts along both axis choices and checked (scripts/sweep.sh);
# and TetGen alone (tetgen -pYQ) on each part, since a run that falls back to one piece must be one
# TetGen alone can do. Exit 0 when every run passed its check.
# Usage: sweep_thin_walls.sh [-p PARTET] [-k "K..."] [-a "auto pca"] [-r "WALL:GAP ..."] [-t "TURN ..."] [-j JOBS]
set -uo pipefail
source "$(dirname "$0")/common.sh"
ks=$(seq -s ' ' 2 16) axes="auto pca" ratios="1:1 1:2 2:1 0.5:2" turns="0 30" jobs=2
while getopts "p:k:a:r:t:j:" opt; do
  case $opt in
    p) partet=$OPTARG ;; k) ks=$OPTARG ;; a) axes=$OPTARG ;; r) ratios=$OPTARG ;; t) turns=$OPTARG ;; j) jobs=$OPTARG ;;
    *) sed -n '2,6p' "$0"; exit 2 ;;
  esac
done
partet=$(realpath "$partet")
make_work_dir
mkdir "$work/parts"
for kind in fins comb slots plates; do
  for ratio in $ratios; do
    for turn in $turns; do
      name="${kind}_w${ratio%%:*}_g${ratio##*:}_t${turn}"
      "$partet" generate "$kind" --wall "${ratio%%:*}" --gap "${ratio##*:}" --turn "$turn" -o "$work/parts/$name.off" > /dev/null || exit 1
    done
  done
done
tetgen_alone=0 tetgen_failed=""
for f in "$work/parts"/*.off; do
  if (cd "$work" && timeout 120 tetgen -pYQ "$f" > /dev/null 2>&1); then tetgen_alone=$((tetgen_alone + 1))
  else tetgen_failed+=" $(basename "$f" .off)"; fi
  rm -f "${f%.off}".1.*
done
echo "TetGen alone (tetgen -pYQ) meshes $tetgen_alone of $(ls "$work/parts" | wc -l) parts${tetgen_failed:+; not:$tetgen_failed}"
"$here/sweep.sh" -p "$partet" -d "$work/parts" -k "$ks" -a "$axes" -j "$jobs"
