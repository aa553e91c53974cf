#!/usr/bin/env bash
# Runs on other nodes of a shared filesystem never take a live run's temporaries for leftovers.
# "Nodes" are PID + UTS namespaces (their own hostname and process numbers) on the same
# filesystem: a pid of one means nothing in the other, so only the owner's lock can tell.
#   1. Node A's run has written its files and waits to publish (its temporaries aged to look
#      old); a run on node B at the same prefix starts, cleans up and publishes: A's temporaries
#      are untouched, and A then publishes its own complete set.
#   2. Node A's run is killed while its temporaries exist: a run on node B removes them.
#   3. On this host: a killed run's temporaries are removed at once; a live run's are kept.
# Exit 77 (skipped) where namespaces cannot be made.
# Usage: other_node.sh PARTET
set -uo pipefail
partet=$(realpath "$1")
unshare --pid --uts --fork --mount-proc true 2> /dev/null || { echo "SKIP: unshare --pid --uts not permitted"; exit 77; }
source "$(dirname "$0")/../harness.sh"
cd "$work"
"$partet" generate torus --faces 3000 -o torus.off > /dev/null
"$partet" mesh torus.off -o a_alone -k 3 --quiet  # what node A's run writes
on_node() {  # NODE COMMAND...: runs COMMAND in a fresh PID and UTS namespace named NODE
  local node=$1
  shift
  unshare --pid --uts --fork --mount-proc bash -c 'hostname "$0"; exec "$@"' "$node" "$@"
}
temporaries() { ls | grep '\.tmp-' | sort | tr '\n' ' '; }
wait_for_temporaries() {  # COUNT
  for i in $(seq 200); do [ "$(ls | grep -c '\.tmp-')" -ge "$1" ] && return 0; sleep 0.05; done
  return 1
}

# 1. A live run on node A, B starts beside it.
on_node nodea env PARTET_TEST_PAUSE_BEFORE_PUBLISH_MS=5000 "$partet" mesh "$work/torus.off" -o "$work/m" -k 3 \
  --quiet > log.a 2>&1 &
a=$!
wait_for_temporaries 4 || bad "node A wrote no temporaries"
touch -d '-10 minutes' m.*.tmp-*  # old enough that only the lock tells they are alive
before=$(temporaries)
on_node nodeb "$partet" mesh "$work/torus.off" -o "$work/m" -k 2 --quiet > log.b 2>&1
code_b=$?
after=$(temporaries)
[ "$code_b" -eq 0 ] && [ "$before" = "$after" ] && ok "node B's run published and left node A's live temporaries alone" ||
  bad "node B: exit $code_b; temporaries before: $before; after: $after; $(cat log.b)"
wait "$a"
code_a=$?
[ "$code_a" -eq 0 ] && [ -z "$(temporaries)" ] && "$partet" check torus.off m > log 2>&1 &&
  cmp -s m.ele a_alone.ele && cmp -s m.node a_alone.node &&
  ok "node A's run then published its own set (check passed)" || bad "node A: exit $code_a: $(cat log.a; cat log)"

# 2. Node A's run is killed (its whole node) while its temporaries exist: node B removes them.
on_node nodea env PARTET_TEST_PAUSE_BEFORE_PUBLISH_MS=30000 "$partet" mesh "$work/torus.off" -o "$work/m" -k 3 \
  --quiet > log.a 2>&1 &
a=$!
wait_for_temporaries 4 || bad "node A wrote no temporaries"
pkill -KILL -f "PAUSE_BEFORE_PUBLISH_MS=30000" 2> /dev/null
pkill -KILL -f "mesh $work/torus.off -o $work/m -k 3" 2> /dev/null
wait "$a" 2> /dev/null
touch -d '-10 minutes' m.*.tmp-*
left=$(temporaries)
on_node nodeb "$partet" mesh "$work/torus.off" -o "$work/m" -k 2 --quiet > log.b 2>&1
[ -n "$left" ] && [ -z "$(temporaries)" ] && ok "node B removed the temporaries of node A's killed run" ||
  bad "killed run's temporaries: before $left; after $(temporaries)"

# 3. On this host: a killed run's temporaries go at once; a live run's stay.
PARTET_TEST_PAUSE_BEFORE_PUBLISH_MS=30000 "$partet" mesh torus.off -o m -k 3 --quiet > log.a 2>&1 &
a=$!
wait_for_temporaries 4 || bad "no temporaries"
"$partet" mesh torus.off -o m -k 2 --quiet > log.b 2>&1
[ "$(ls | grep -c "\.tmp-$a-")" -eq 4 ] && ok "a live run's temporaries on this host are kept" || bad "live run's temporaries: $(temporaries)"
kill -KILL "$a"
wait "$a" 2> /dev/null
"$partet" mesh torus.off -o m -k 2 --quiet > log.b 2>&1
[ -z "$(temporaries)" ] && ok "a killed run's temporaries on this host are removed by the next run" ||
  bad "killed run's temporaries: $(temporaries)"

summary
