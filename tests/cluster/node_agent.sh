#!/bin/sh
# mpirun's launch agent in tests/cluster/namespaces.sh, where a cluster uses ssh: runs a command on
# a "node": in its network namespace, under its own hostname, with its own scratch directory (a
# tmpfs over $PARTET_NODE_SCRATCH, as TMPDIR). $PARTET_NODES lists "address namespace hostname".
# Called as: node_agent.sh HOST COMMAND... (the command is shell text, as ssh would run it).
host=$1
shift
set -- "$(grep "^$host " "$PARTET_NODES")" "$*"
[ -n "$1" ] || { echo "node_agent: unknown node $host" >&2; exit 1; }
namespace=$(echo "$1" | cut -d' ' -f2) name=$(echo "$1" | cut -d' ' -f3)
exec ip netns exec "$namespace" unshare --uts --mount --propagation private sh -c '
  hostname "$1" && mount -t tmpfs tmpfs "$PARTET_NODE_SCRATCH" && export TMPDIR="$PARTET_NODE_SCRATCH" && exec sh -c "$2"' \
  node "$name" "$2"
