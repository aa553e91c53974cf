# Sourced by the cluster tests: nodes on one machine, as a cluster has them. make_nodes COUNT
# makes COUNT network namespaces, each with its own address on a private bridge (a veth pair per
# node, on a /24 of this process's own), reachable from here at $net.1. It sets
#   net     the /24's first three numbers        bridge  the bridge's name
#   nodes   the namespaces' names (node i: ${nodes[i]}, address ${hosts[i]} = $net.(i+2))
# remove_nodes removes them (call it on exit). A node's own hostname, /tmp or scratch are made by
# what runs in it (unshare --uts --mount).
make_nodes() {
  local count=$1 tag=$(($$ % 100000)) i ns
  net="10.$(($$ % 200 + 20)).$(($$ / 200 % 250))"
  bridge=ptb$tag
  nodes=() hosts=()
  for ((i = 0; i < count; i++)); do nodes+=("ptn${tag}n$i"); done
  ip link add "$bridge" type bridge
  ip addr add "$net.1/24" dev "$bridge"
  ip link set "$bridge" up
  for ((i = 0; i < count; i++)); do
    ns=${nodes[$i]}
    ip netns add "$ns"
    ip link add "v$tag$i" type veth peer name "e$tag$i"
    ip link set "e$tag$i" netns "$ns"
    ip link set "v$tag$i" master "$bridge" up
    ip -n "$ns" addr add "$net.$((i + 2))/24" dev "e$tag$i"
    ip -n "$ns" link set "e$tag$i" up
    ip -n "$ns" link set lo up
    hosts+=("$net.$((i + 2))")
  done
}

remove_nodes() {
  local ns
  for ns in "${nodes[@]}"; do ip netns del "$ns" 2> /dev/null || true; done
  [ -z "${bridge:-}" ] || ip link del "$bridge" 2> /dev/null || true
}

# Whether this process may make nodes (root, ip netns, unshare).
can_make_nodes() {
  local probe=ptprobe$$
  [ "$(id -u)" -eq 0 ] && ip netns add "$probe" 2> /dev/null && ip netns del "$probe" &&
    unshare --uts --mount true 2> /dev/null
}
