#!/usr/bin/env bash
# The ranks that meshed the pieces keep their band parts and cut the seam chains' shares of them.
# A rank that cannot (PARTET_INJECT_FAILURE=worker:shares-error: rank 1 fails to cut any) must not
# cost the run: every chain it has a share of fails, rank 0 says so, takes the band parts back,
# heals the seams over the whole mesh, and the job ends with exit code 0, a mesh that passes the
# check, and as many tets as on one rank. On 3 ranks rank 2 heals chains too: one that failed
# there (from the empty message rank 1 sends it straight) must be named by rank 2 itself. With
# FORMAT=xdmf in the environment the XDMF set alone is written, so the chains healed on other
# ranks stay there (HealOptions::keep_healed): those must come back to rank 0 when one failed.
# Usage: shares_failure.sh PARTET MPIEXEC [RANKS]
set -uo pipefail
partet=$1 mpiexec=$2 ranks=${3:-2} format=${FORMAT:-tetgen}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; cat "$work/log" 2>/dev/null; exit 1; }
"$partet" generate torus --faces 20000 -o "$work/torus.off" >/dev/null || exit 1
tets_of() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["counts"]["output_tets"])' "$1"; }
"$partet" mesh "$work/torus.off" -o "$work/one" --pieces 12 --report "$work/one.json" > "$work/log" 2>&1 ||
  fail "one rank: exit code $?"
PARTET_INJECT_FAILURE=worker:shares-error timeout -k 5 120 "$mpiexec" -n "$ranks" --oversubscribe -x PARTET_INJECT_FAILURE \
  "$partet" mesh "$work/torus.off" -o "$work/out" --pieces 12 --format "$format" --report "$work/report.json" \
  > "$work/log" 2>&1
code=$?
[ "$code" -ne 124 ] || fail "the job hung (killed after 120 s)"
[ "$code" -eq 0 ] || fail "exit code $code: a rank that cannot cut its shares must not end the job"
expected="seam chain [0-9]+ could not be gathered from its pieces' shares: .*rank 1 could not cut its shares"
grep -qE "$expected" "$work/log" || fail "no warning naming the chain and rank 1"
grep -q "injected failure to cut the shares" "$work/log" || fail "rank 1's own message is not in the log"
# (Whether rank 2 heals a chain with rank 1's shares depends on which rank meshed which piece.)
if (( ranks >= 3 )) && grep -q "on rank 2, failed)" "$work/log"; then
  grep -qE "^partet\[rank 2\]: .*$expected" "$work/log" || fail "rank 2 did not say which chain it could not gather"
fi
if [ "$format" = xdmf ] && grep -qE "healed \(chain [0-9]+ on rank [1-9][0-9]*\)" "$work/log"; then
  grep -q "took back the [1-9][0-9]* healed seam chains kept where they healed" "$work/log" ||
    fail "the chains healed on other ranks did not come back to rank 0"
fi
[ "$(tets_of "$work/report.json")" = "$(tets_of "$work/one.json")" ] ||
  fail "$(tets_of "$work/report.json") tets, one rank gave $(tets_of "$work/one.json")"
out=$work/out
[ "$format" = xdmf ] && out=$work/out.xdmf
"$partet" check "$work/torus.off" "$out" > "$work/check" 2>&1 || fail "the mesh fails its check: $(cat "$work/check")"
echo "ok: exit $code, $(grep -m1 -oE "$expected" "$work/log")"
