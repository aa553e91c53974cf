#!/usr/bin/env bash
# Meshes INPUT with K pieces on 1, 2 and 4 (oversubscribed) ranks and requires byte-identical
# output files, each passing `partet check`. With MIN_CHAINS=N in the environment, the seams must
# form at least N chains (each healed whole on a rank of its own on 2 and 4 ranks); with
# MIN_BANDS_GROWN=N, on 2 ranks at least N bands a neighbour's crossing reached must have grown
# where their bulks were kept (the report's bands_grown: the bulks did not travel); with
# SHARES_CUT=1, rank 1 must have cut its shares of the seam chains from the band parts it kept
# (share_cut_seconds); with CHAINS_AHEAD=1, rank 0 must have gathered a chain ahead for rank 1
# while it healed one and rank 1 healed another (its log on 2 ranks); with DIRECT_SHARES=1, the
# other ranks must have healed chains from shares that never passed through rank 0, their own or
# sent straight by another worker (chain_shares_direct, on 2 and 4 ranks), and no chain may have
# failed (a share gone astray would make its chain fail, and the seams heal over the whole mesh).
# With XDMF=1, the XDMF set alone (--format xdmf) is written on 1, 2 and 4 ranks too and its .h5
# files must be byte-identical; the seam chains healed on other ranks than 0 then stay there
# (chains_kept), and at least one must have on 2 or 4 ranks.
# Usage: determinism.sh PARTET MPIEXEC INPUT|generated:SHAPE[:FACES] K [partet mesh options...]
set -euo pipefail
partet=$1 mpiexec=$2 input=$3 k=$4
shift 4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [[ $input == generated:* ]]; then
  shape=${input#generated:} faces=4000
  [[ $shape == *:* ]] && faces=${shape#*:} shape=${shape%%:*}
  "$partet" generate "$shape" --faces "$faces" -o "$work/input.off" >/dev/null
  input=$work/input.off
fi
"$partet" mesh "$input" -o "$work/n1" --pieces "$k" --quiet "$@"
"$mpiexec" -n 2 "$partet" mesh "$input" -o "$work/n2" --pieces "$k" --verbose --report "$work/n2.json" "$@" > "$work/n2.log" 2>&1 ||
  { cat "$work/n2.log"; exit 1; }
"$mpiexec" -n 4 --oversubscribe "$partet" mesh "$input" -o "$work/n4" --pieces "$k" --verbose --report "$work/n4.json" "$@" \
  > "$work/n4.log" 2>&1 || { cat "$work/n4.log"; exit 1; }
"$partet" check "$input" "$work/n1" | tail -n 1 | grep -q "check passed"
for n in n2 n4; do
  for ext in node ele face neigh; do
    cmp "$work/n1.$ext" "$work/$n.$ext" || { echo "FAIL: $n.$ext differs from the 1-rank output"; exit 1; }
  done
done
read -r chains grown cut direct <<< "$(/usr/bin/python3 -c "
import json, sys
r, r4 = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
direct = lambda r: sum(x['chain_shares_direct'] for x in r['rank'][1:])
print(r['counts']['seam_chains'], int(sum(x['bands_grown'] for x in r['rank'])), int(r['rank'][1]['share_cut_seconds'] > 0),
      int(min(direct(r), direct(r4))))" "$work/n2.json" "$work/n4.json")"
if (( chains < ${MIN_CHAINS:-0} )); then echo "FAIL: $chains chains of cuts, expected at least $MIN_CHAINS"; exit 1; fi
if (( ${SHARES_CUT:-0} && cut == 0 )); then echo "FAIL: rank 1 cut no shares of the seam chains (share_cut_seconds)"; exit 1; fi
if (( ${DIRECT_SHARES:-0} && direct == 0 )); then echo "FAIL: no rank healed a chain from shares kept off rank 0 (chain_shares_direct)"; exit 1; fi
if (( ${DIRECT_SHARES:-0} )) && grep -E "could not be (gathered|welded)|, failed\)" "$work/n2.log" "$work/n4.log"; then
  echo "FAIL: a seam chain failed"; exit 1
fi
if (( ${CHAINS_AHEAD:-0} )) && ! grep -q "gathered ahead for rank 1" "$work/n2.log"; then
  echo "FAIL: no seam chain gathered ahead for rank 1 on 2 ranks"; exit 1
fi
if (( grown < ${MIN_BANDS_GROWN:-0} )); then echo "FAIL: $grown bands grown where their bulks were kept, expected at least $MIN_BANDS_GROWN"; exit 1; fi
if (( ${XDMF:-0} )); then
  "$partet" mesh "$input" -o "$work/x1" --pieces "$k" --quiet --format xdmf "$@"
  for n in 2 4; do
    "$mpiexec" -n $n --oversubscribe "$partet" mesh "$input" -o "$work/x$n" --pieces "$k" --verbose --format xdmf \
      --report "$work/x$n.json" "$@" > "$work/x$n.log" 2>&1 || { cat "$work/x$n.log"; exit 1; }
    for file in x.h5 x_boundary.h5; do
      cmp "$work/x1${file#x}" "$work/x$n${file#x}" || { echo "FAIL: the XDMF set's ${file#x} on $n ranks differs"; exit 1; }
    done
  done
  "$partet" check "$input" "$work/x4.xdmf" | tail -n 1 | grep -q "check passed"
  kept=$(/usr/bin/python3 -c "
import json, sys
print(int(sum(x['chains_kept'] for f in sys.argv[1:] for x in json.load(open(f))['rank'][1:])))" "$work/x2.json" "$work/x4.json")
  if (( kept == 0 )); then echo "FAIL: no seam chain stayed on the rank that healed it (chains_kept)"; exit 1; fi
  echo "identical XDMF sets on 1, 2 and 4 ranks ($kept seam chains kept where they healed)"
fi
echo "identical output on 1, 2 and 4 ranks (k=$k $*; $chains chains of cuts, $grown bands grown by their owners)"
