#!/usr/bin/env bash
# --scratch DIR (the paper's memory mode): the pieces' bulks wait in a file there, and the mesh is
# the same, byte for byte, as without (on several ranks without a quality bound, written from the
# ranks that meshed the pieces, as without --scratch); nothing stays in DIR after a run, nor after
# an interrupt (SIGTERM while the bulks are there), nor after a kill (SIGKILL: the file has no
# name in DIR, so the system frees it); a DIR that is not a directory is a usage error (exit 2)
# before any work.
# With MPIEXEC and its arguments, every run is on those ranks.
# Usage: scratch.sh PARTET [MPIEXEC ARGS...]
set -uo pipefail
partet=$(realpath "$1")
shift
launch=("$@")
source "$(dirname "$0")/../harness.sh"
cd "$work"
run() { "${launch[@]}" "$partet" "$@"; }
"$partet" generate torus --faces 20000 -o torus.off > /dev/null
"$partet" generate genus3 --faces 400000 -o big.off > /dev/null
mkdir scratch

# 1. The same bytes, with and without a quality bound; DIR is empty after. Every bulk waited on disk:
# rank 0's, and on several ranks without a quality bound those the ranks that meshed them kept.
for quality in "" "1.414"; do
  q=(); [ -n "$quality" ] && q=(-q "$quality")
  run mesh torus.off -k 6 "${q[@]}" -o a --report a.json --quiet || bad "q='$quality': without --scratch"
  run mesh torus.off -k 6 "${q[@]}" -o b --scratch scratch --report b.json --quiet || bad "q='$quality': with --scratch"
  same=1
  for f in node ele face neigh; do cmp -s a.$f b.$f || same=0; done
  read -r bulks kept on_disk assembled < <(python3 -c "import json; r = json.load(open('b.json'))
print(r['scratch']['bulks'], r['bulks_where_meshed'], int(sum(x['bulks_on_disk'] for x in r['rank'])), r['assembled_on_rank0'])")
  left=$(ls -A scratch)
  # (On several ranks, which pieces rank 0 meshes itself depends on timing.)
  if [ $same = 1 ] && [ $((bulks + kept)) -ge 6 ] && [ "$kept" = "$on_disk" ] &&
     { [ ${#launch[@]} -gt 0 ] || [ "$bulks" = 6 ]; } && [ -z "$left" ]; then
    ok "q='$quality': the same files with --scratch; of 6 bulks, $bulks waited on rank 0's disk, $on_disk on the disk of the ranks that meshed them; nothing left"
  else bad "q='$quality': same=$same bulks=$bulks kept=$kept on_disk=$on_disk left='$left'"; fi
  # Without a quality bound, on several ranks, the bulks came back from disk to the rank that
  # meshed them for the writes: rank 0 did not assemble the mesh (one process always does).
  if [ -z "$quality" ]; then
    want=True; [ ${#launch[@]} -gt 0 ] && want=False
    [ "$assembled" = $want ] && ok "q='': assembled on rank 0: $assembled, as expected with --scratch" ||
      bad "q='': assembled on rank 0: $assembled, expected $want"
  fi
  # Without --scratch, the ranks that kept bulks in memory numbered them there before the assembly.
  read -r kept numbering < <(python3 -c "import json; r = json.load(open('a.json'))
print(r['bulks_where_meshed'], sum(x['bulk_number_seconds'] for x in r['rank'] if x['bulks_kept'] > 0) > 0)")
  if [ "$kept" -gt 0 ]; then
    [ "$numbering" = True ] && ok "q='$quality': the ranks that kept $kept bulks numbered them (bulk_number_seconds)" ||
      bad "q='$quality': $kept bulks kept on other ranks, but no rank reports numbering them"
  fi
done

# 2. Not a directory: exit 2 before any work, naming the option.
run mesh torus.off -o c --scratch missing > log 2>&1
code=$?
if [ $code = 2 ] && grep -q -- "--scratch: 'missing' is not a directory" log && [ ! -e c.node ]; then
  ok "a missing scratch directory: exit 2, says so, writes nothing"
else bad "a missing scratch directory: exit $code: $(cat log)"; fi

# Whether a process of the big run holds a file in scratch/ with bulks in it (a file without a
# name there shows as "DIR/#inode (deleted)").
bulks_held() {
  local p fd
  for p in $(pgrep -f "mesh $work/big.off"); do
    for fd in /proc/"$p"/fd/*; do
      [[ "$(readlink "$fd" 2> /dev/null)" == "$work/scratch/"* ]] && [ "$(stat -L -c %s "$fd" 2> /dev/null || echo 0)" -gt 0 ] &&
        return 0
    done
  done
  return 1
}

# Starts a run of the big input and waits until it holds bulks in scratch/ (false once it ended,
# or after 300 s: under a loaded CI the pieces take long).
start_big() {
  "${launch[@]}" "$partet" mesh "$work/big.off" -k 8 -o d --scratch scratch --quiet > log 2>&1 &
  pid=$!
  wait_while_running 300 bulks_held
}

# Waits (30 s at most) until no process of the big run is left.
gone_big() { wait_gone 30 "mesh $work/big.off"; }

give_up() {
  local state="the run had ended"
  kill -0 "$pid" 2> /dev/null && state="still running after 300 s"
  bad "no bulk reached the scratch directory ($state): $(cat log)"
  kill -KILL "$pid" 2> /dev/null
  wait "$pid"
}

# 3. SIGTERM while bulks wait on disk (to the launcher, with one): it fails (143 in one process),
# writes no output, leaves DIR empty.
if start_big; then
  kill -TERM "$pid"
  wait "$pid"
  code=$?
  gone_big  # under mpirun the ranks may still be removing their files when the launcher has ended
  left=$(ls -A scratch)
  if { [ $code = 143 ] || { [ ${#launch[@]} -gt 0 ] && [ $code != 0 ]; }; } && [ -z "$left" ] && [ ! -e d.node ]; then
    ok "SIGTERM with bulks on disk: exit $code, nothing left"
  else bad "SIGTERM with bulks on disk: exit $code, left '$left': $(cat log)"; fi
else give_up; fi

# 4. SIGKILL of every process while bulks wait on disk leaves nothing in DIR either; the next run
# with the same DIR works.
if start_big; then
  # (The pattern names this test's directory: another test may run the same command meanwhile.)
  pkill -KILL -f "mesh $work/big.off" 2> /dev/null
  wait "$pid" 2> /dev/null
  gone_big
  killed=$(ls -A scratch)
  run mesh torus.off -k 3 -o e --scratch scratch --quiet || bad "the run after a SIGKILL failed"
  left=$(ls -A scratch)
  if [ -z "$killed" ] && [ -z "$left" ]; then ok "SIGKILL with bulks on disk: nothing left; the next run works"
  else bad "after a SIGKILL: left '$killed', then '$left'"; fi
else give_up; fi

summary
