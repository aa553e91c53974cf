#!/usr/bin/env bash
# Runs the recipe cluster/mpirun-hostfile.sh unchanged, with a hostfile naming this machine with
# two slots, on a generated surface: it must mesh and end with a passed check.
# Usage: hostfile.sh PARTET
set -euo pipefail
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export PARTET=$(realpath "$1")
"$PARTET" generate genus3 --faces 4000 -o "$work/genus3.off" > /dev/null
echo "localhost slots=2" > "$work/hosts"
"$(dirname "$0")/../../cluster/mpirun-hostfile.sh" "$work/hosts" "$work/genus3.off" "$work/out/genus3" > "$work/log" 2>&1 \
  || { cat "$work/log"; echo "FAIL: the recipe failed"; exit 1; }
tail -n 1 "$work/log" | grep -q "check passed" || { cat "$work/log"; echo "FAIL: no passed check"; exit 1; }
[ -s "$work/out/genus3.report.json" ] || { echo "FAIL: no report"; exit 1; }
echo "ok: $(tail -n 1 "$work/log")"
