#!/usr/bin/env bash
# Three nodes on one machine, as a cluster has them: each a network namespace with its own address
# (a veth pair on a private bridge the test makes), its own hostname (UTS namespace) and its own
# scratch directory (a private tmpfs mounted at the same path, as a node-local /tmp is), all
# sharing one output directory (as a parallel filesystem is shared). mpirun, outside them, starts
# its daemons in the nodes through a launch agent (tests/cluster/node_agent.sh) where a cluster
# would use ssh, and the ranks talk over TCP between the nodes' addresses only.
#
# On these nodes partet meshes a generated surface into TetGen files, the XDMF set (whose HDF5
# files all three ranks write at once into the shared directory), a .pvtu set and the MSH
# partitions (whose files the three ranks write, whichever is free); the files must be
# byte-identical to a 1-process run's, pass `partet check`, and DOLFINx, run on the three nodes, must read the
# XDMF set back with the same tets, boundary facets and volume; `partet check` on the three nodes,
# each rank checking its part of the XDMF set, must pass.
# Needs root (ip netns, unshare, mount); exits 77 (skipped) without them.
# Usage: namespaces.sh PARTET MPIEXEC
set -euo pipefail
partet=$(realpath "$1") mpiexec=$2
here=$(cd "$(dirname "$0")" && pwd)
source "$here/nodes.sh"
nodes=() bridge=""
work=$(mktemp -d)

cleanup() {
  remove_nodes
  rm -rf "$work"
}
trap cleanup EXIT

if ! can_make_nodes; then
  echo "skipped: needs root with ip netns and unshare"
  exit 77
fi
make_nodes 3
for i in 0 1 2; do echo "${hosts[$i]} ${nodes[$i]} node$((i + 1))" >> "$work/nodes"; done  # address, namespace, hostname

mkdir -p "$work/shared" "$work/scratch"
export PARTET_NODES=$work/nodes PARTET_NODE_SCRATCH=$work/scratch
mpirun_nodes=("$mpiexec" --host "$(IFS=,; echo "${hosts[*]/%/:1}")" -n 3
  --mca plm_rsh_agent "$here/node_agent.sh" --mca plm_rsh_no_tree_spawn 1
  --mca oob_tcp_if_include "$net.0/24" --mca btl self,tcp --mca btl_tcp_if_include "$net.0/24")

# Where the ranks run: three hostnames, three addresses, each with a scratch directory no other
# node sees (each writes a file there and must find only its own).
"${mpirun_nodes[@]}" sh -c 'touch "$TMPDIR/mine.$(hostname)"; sleep 1
  echo "$(hostname) $(ip -4 -o addr show scope global | awk "{print \$4}") $(cd "$TMPDIR" && ls mine.* | tr "\n" " ")"' \
  | sort > "$work/where"
cat "$work/where"
[ "$(cut -d' ' -f1 "$work/where" | sort -u | wc -l)" -eq 3 ] || { echo "FAIL: the ranks did not run on 3 hosts"; exit 1; }
while read -r host address files; do
  [ "$files" = "mine.$host" ] || { echo "FAIL: $host's scratch holds '$files'"; exit 1; }
done < "$work/where"

cd "$work/shared"
"$partet" generate genus3 --faces 6000 -o in.off > /dev/null
"$partet" mesh in.off -o one --pieces 6 --format tetgen,xdmf,pvtu,msh-parts --quiet
"${mpirun_nodes[@]}" "$partet" mesh "$work/shared/in.off" -o "$work/shared/nodes" --pieces 6 --format tetgen,xdmf,pvtu,msh-parts \
  --report "$work/shared/nodes.json" --quiet
ranks=$(/usr/bin/python3 -c "import json; print(json.load(open('nodes.json'))['ranks'])")
[ "$ranks" -eq 3 ] || { echo "FAIL: the report says $ranks ranks"; exit 1; }
for file in .node .ele .face .neigh .h5 _boundary.h5 _seams.vtu _p{0..5}.vtu _{1..7}.msh; do
  cmp "one$file" "nodes$file" || { echo "FAIL: nodes$file differs from the 1-process run's"; exit 1; }
done
written=$(/usr/bin/python3 -c "import json; print(' '.join(str(int(r['piece_files_written'])) for r in json.load(open('nodes.json'))['rank']))")
read -r on1 on2 on3 <<< "$written"
[ $((on1 + on2 + on3)) -eq 14 ] && [ "$on2" -ge 1 ] && [ "$on3" -ge 1 ] ||
  { echo "FAIL: piece files written per node: $written"; exit 1; }
"$partet" check in.off nodes | tail -n 1
# The XDMF set checked on the three nodes, each rank its part.
"${mpirun_nodes[@]}" "$partet" check "$work/shared/in.off" "$work/shared/nodes.xdmf" | tail -n 2
"${mpirun_nodes[@]}" /usr/bin/python3 "$here/../formats/dolfinx_read.py" "$work/shared/nodes" 2>&1 | grep -v "^INFO:"
echo "ok: 3 ranks on 3 namespace nodes wrote the same files as 1 process (the 14 files of the .pvtu set and the MSH partitions: $written per node); DOLFINx read them on the 3 nodes"
