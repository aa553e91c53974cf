#!/usr/bin/env bash
# The caps are triangulated on whichever rank is free (rank 0 deals them out before the pieces).
# A cap that fails on another rank must be rank 0's own failure: PARTET_INJECT_FAILURE=
# worker:cap-error makes every cap built on a rank other than 0 fail as crossing loops would.
# On 1 rank nothing fails (rank 0 builds every cap); on RANKS ranks the job retries with other
# cuts, names the failure (its plane and message travel from the worker), and, since every cut
# fails, ends with the input meshed as one piece, exit code 0, and a mesh that passes the check.
# Usage: cap_failure.sh PARTET MPIEXEC RANKS
set -uo pipefail
partet=$1 mpiexec=$2 ranks=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; cat "$work/log" 2>/dev/null; exit 1; }
"$partet" generate torus --faces 3000 -o "$work/torus.off" >/dev/null || exit 1
pieces_of() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["pieces"])' "$1"; }

PARTET_INJECT_FAILURE=worker:cap-error timeout -k 5 60 "$mpiexec" -n 1 -x PARTET_INJECT_FAILURE \
  "$partet" mesh "$work/torus.off" -o "$work/one" --pieces 4 --report "$work/one.json" > "$work/log" 2>&1 ||
  fail "one rank: exit code $?"
[ "$(pieces_of "$work/one.json")" = 4 ] || fail "one rank: not meshed in 4 pieces"

PARTET_INJECT_FAILURE=worker:cap-error timeout -k 5 60 "$mpiexec" -n "$ranks" --oversubscribe \
  -x PARTET_INJECT_FAILURE "$partet" mesh "$work/torus.off" -o "$work/out" --pieces 4 \
  --report "$work/report.json" > "$work/log" 2>&1
code=$?
[ "$code" -ne 124 ] || fail "the job hung (killed after 60 s)"
[ "$code" -eq 0 ] || fail "exit code $code: a cap failure must be retried like any cut failure"
grep -q "cut plane [0-9]*: injected cap failure" "$work/log" || fail "no message naming the failed cap's plane"
[ "$(pieces_of "$work/report.json")" = 1 ] || fail "not meshed as one piece although every cap on a worker fails"
python3 - "$work/report.json" <<'PY' || fail "the report does not show the caps built on the workers"
import json, sys
report = json.load(open(sys.argv[1]))
assert any("injected cap failure" in r["reason"] for r in report["retries"]), report["retries"]
assert sum(r["caps"] for r in report["rank"][1:]) >= 1, report["rank"]
PY
"$partet" check "$work/torus.off" "$work/out" > "$work/check" 2>&1 || fail "the mesh fails its check: $(cat "$work/check")"
echo "ok: $ranks ranks, exit $code, $(grep -m1 'injected cap failure' "$work/log")"
