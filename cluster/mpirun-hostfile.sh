#!/usr/bin/env bash
# partet on a cluster without Slurm: mpirun over the hosts of a hostfile.
#
# Usage: cluster/mpirun-hostfile.sh HOSTFILE INPUT PREFIX [PIECES]
#   HOSTFILE  OpenMPI hostfile, one line per node: "node01 slots=16" (slots = cores for ranks)
#   INPUT     closed surface (.off/.obj/.stl/.ply), read by rank 0 only
#   PREFIX    output prefix (PREFIX.node/.ele/.face/.neigh, PREFIX.report.json), written by rank 0
#   PIECES    pieces (default: 2 x ranks; more pieces = less memory per rank, better balance)
# Environment: RANKS (default: all slots of the hostfile), PARTET (the binary, default `partet`),
#   MPIRUN_ARGS (more mpirun arguments, e.g. "--mca btl self,tcp" where shared memory is missing).
#
# Only rank 0 touches files: the input and the output need to exist on the first host only; the
# other hosts need the partet binary (same path) and nothing else. Ranks are bound to cores and
# each rank's TetGen child inherits its core: the rank sleeps while its child meshes.
set -euo pipefail
hostfile=${1:?hostfile} input=${2:?input surface} prefix=${3:?output prefix}
partet=${PARTET:-partet}
slots=$(awk '!/^[[:space:]]*(#|$)/ { n = 1; for (i = 2; i <= NF; ++i) if ($i ~ /^slots=/) n = substr($i, 7); s += n } END { print s + 0 }' "$hostfile")
ranks=${RANKS:-$slots}
pieces=${4:-$((2 * ranks))}
mkdir -p "$(dirname "$prefix")"
# shellcheck disable=SC2086  # MPIRUN_ARGS is a list of words
mpirun --hostfile "$hostfile" -np "$ranks" --map-by core --bind-to core:overload-allowed ${MPIRUN_ARGS:-} \
  "$partet" mesh "$input" -o "$prefix" --pieces "$pieces" --report "$prefix.report.json"
"$partet" check "$input" "$prefix"
