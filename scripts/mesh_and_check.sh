#!/usr/bin/env bash
# Meshes INPUT with K pieces and verifies the result with `partet check`.
# Usage: mesh_and_check.sh PARTET INPUT K OUTDIR [extra partet mesh options...]
# Under MPI set PARTET_LAUNCH, e.g. PARTET_LAUNCH="mpiexec -n 2".
set -euo pipefail
partet=$1 input=$2 k=$3 outdir=$4
shift 4
mkdir -p "$outdir"
prefix="$outdir/$(basename "${input%.*}")_k$k"
rm -f "$prefix".node "$prefix".ele "$prefix".face "$prefix".neigh
timeout "${PARTET_TIMEOUT:-600}" ${PARTET_LAUNCH:-} "$partet" mesh "$input" -o "$prefix" --pieces "$k" --quiet "$@"
"$partet" check "$input" "$prefix" | tail -n 3
rm -f "$prefix".node "$prefix".ele "$prefix".face "$prefix".neigh
