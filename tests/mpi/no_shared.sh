#!/usr/bin/env bash
# Nothing may assume shared memory or a shared working directory between ranks.
#   tcp:  ranks talk over TCP only (--mca btl self,tcp); the output must be byte-identical to a
#         1-rank run's.
#   dirs: each rank starts in its own empty working directory; input and output are relative
#         paths that exist only in rank 0's. The workers' directories must stay empty, and the
#         output must again be byte-identical.
# Both write the XDMF set too, whose HDF5 files every rank writes into (at rank 0's path), and a
# .pvtu set and the MSH partitions, whose files the ranks write (at rank 0's paths).
# Usage: no_shared.sh PARTET MPIEXEC tcp|dirs
set -euo pipefail
partet=$1 mpiexec=$2 mode=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/rank0/out" "$work/rank1" "$work/rank2"
"$partet" generate genus3 --faces 4000 -o "$work/rank0/input.off" > /dev/null
"$partet" mesh "$work/rank0/input.off" -o "$work/serial" --pieces 4 --quiet --format tetgen,xdmf,pvtu,msh-parts-binary
case $mode in
  tcp)
    "$mpiexec" -n 2 --mca btl self,tcp "$partet" mesh "$work/rank0/input.off" -o "$work/rank0/out/m" \
      --pieces 4 --quiet --format tetgen,xdmf,pvtu,msh-parts-binary ;;
  dirs)
    # MPMD: one launch line per rank, each with its own working directory.
    args=(mesh input.off -o out/m --pieces 4 --quiet --format tetgen,xdmf,pvtu,msh-parts-binary)
    "$mpiexec" --oversubscribe -n 1 --wdir "$work/rank0" "$partet" "${args[@]}" \
      : -n 1 --wdir "$work/rank1" "$partet" "${args[@]}" \
      : -n 1 --wdir "$work/rank2" "$partet" "${args[@]}"
    for r in rank1 rank2; do
      left=$(ls -A "$work/$r")
      [ -z "$left" ] || { echo "FAIL: a worker wrote into its working directory: $r/$left"; exit 1; }
    done ;;
  *) echo "unknown mode $mode"; exit 2 ;;
esac
for ext in node ele face neigh h5 _boundary.h5 _seams.vtu _p0.vtu _p1.vtu _p2.vtu _p3.vtu _{1..5}.msh; do
  [[ $ext == _* ]] && file=$ext || file=.$ext
  cmp "$work/serial$file" "$work/rank0/out/m$file" || { echo "FAIL: $file differs from the 1-rank output"; exit 1; }
done
"$partet" check "$work/rank0/input.off" "$work/rank0/out/m" | tail -n 1
echo "ok: $mode: identical to the 1-rank output"
