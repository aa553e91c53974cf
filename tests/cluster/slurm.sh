#!/usr/bin/env bash
# A real Slurm, started by hand: installs Debian's slurmctld, slurmd, slurm-client and munge if
# missing, writes a private configuration (this machine's CPUs and memory, non-default ports, all
# state in a temporary directory), starts munged, slurmctld and slurmd, submits every sbatch
# recipe in cluster/ (unchanged but for its arguments) on INPUT, waits for them, prints each
# job's log (ending with its `partet check` result), suspends and resumes one more job and
# requeues another mid-run (each must give the files of a run outside Slurm), and stops the
# daemons by PID, also on failure.
#
# With --nodes 3 the cluster has three nodes: network namespaces with their own address on a
# private bridge (tests/cluster/nodes.sh), hostname and /tmp, each running its own slurmd, all
# sharing the job directory (as a cluster shares its home or project filesystem). The jobs then
# span the three nodes (srun --mpi=pmix and mpirun inside the allocation, the ranks talking over
# TCP between the nodes' addresses), and their TetGen files and XDMF set must be byte-identical to
# a 1-process run's.
# Usage: tests/cluster/slurm.sh [--nodes 3] PARTET [INPUT]   (INPUT default: a generated genus-3 surface)
# PARTET_KEEP_SLURM=1 keeps the run directory (configuration, daemon and job logs) for a look.
set -euo pipefail
node_count=1
if [ "${1:-}" = --nodes ]; then node_count=$2; shift 2; fi
partet=$(realpath "${1:?partet binary}")
project=$(cd "$(dirname "$0")/../.." && pwd)
source "$project/tests/cluster/nodes.sh"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
if [ "$node_count" -gt 1 ] && ! can_make_nodes; then
  echo "skipped: several nodes need root with ip netns and unshare"
  exit 77
fi

# 1. Packages.
need=()
for p in slurmctld slurmd slurm-client munge; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || need+=("$p")
done
if [ ${#need[@]} -gt 0 ]; then
  echo "slurm test: installing ${need[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${need[@]}" > /dev/null
fi

# 2. A private configuration. Everything lives in $run (outside /tmp, which each node of
# several has of its own); the daemons' PIDs are kept to stop them.
run=$(mktemp -d /var/tmp/partet-slurm.XXXXXX)
chmod 755 "$run"
pids=() nodes=() bridge=""
stop_daemons() {
  for pid in "${pids[@]}" $(cat "$run"/slurmd.*.pid 2>/dev/null); do $SUDO kill "$pid" 2>/dev/null || true; done
  sleep 1
  for pid in "${pids[@]}" $(cat "$run"/slurmd.*.pid 2>/dev/null); do $SUDO kill -9 "$pid" 2>/dev/null || true; done
  remove_nodes
  [ -n "${PARTET_KEEP_SLURM:-}" ] || rm -rf "$run"
}
trap stop_daemons EXIT
user=$(id -un)
host=$(hostname -s)
cpus=$(nproc)
mem_mb=$(awk '/MemTotal/ { printf "%d", $2 / 1024 * 0.9 }' /proc/meminfo)
port=$((20000 + RANDOM % 20000))
mkdir -p "$run/state" "$run/jobs"
if [ "$node_count" -eq 1 ]; then
  controller=$host
  node_lines="NodeName=$host CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN"
  node_list=$host
else
  make_nodes "$node_count"
  controller="$host($net.1)"  # the nodes reach it over the bridge
  node_lines=""
  for ((i = 0; i < node_count; i++)); do
    node_lines+="NodeName=node$((i + 1)) NodeAddr=${hosts[$i]} CPUs=$cpus RealMemory=$((mem_mb / node_count)) State=UNKNOWN"$'\n'
  done
  node_list="node[1-$node_count]"
fi
cat > "$run/slurm.conf" <<CONF
ClusterName=partet-test
SlurmctldHost=$controller
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=$user
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$run/munge.socket
CredType=cred/munge
StateSaveLocation=$run/state
SlurmdSpoolDir=$run/spool.%n
SlurmctldPidFile=$run/slurmctld.pid
SlurmdPidFile=$run/slurmd.%n.pid
SlurmctldLogFile=$run/slurmctld.log
SlurmdLogFile=$run/slurmd.%n.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
MpiDefault=none
ReturnToService=2
SchedulerType=sched/builtin
$node_lines
PartitionName=test Nodes=$node_list Default=YES MaxTime=60 State=UP
CONF
export SLURM_CONF=$run/slurm.conf

# 3. Daemons: munged with its own key and socket, then slurmctld and slurmd.
$SUDO dd if=/dev/urandom of="$run/munge.key" bs=1024 count=1 status=none
$SUDO chmod 400 "$run/munge.key"
$SUDO munged --force --key-file="$run/munge.key" --socket="$run/munge.socket" \
  --pid-file="$run/munged.pid" --log-file="$run/munged.log" --seed-file="$run/munged.seed"
pids+=("$(cat "$run/munged.pid")")
$SUDO env SLURM_CONF="$SLURM_CONF" slurmctld -f "$SLURM_CONF"
for _ in $(seq 50); do [ -s "$run/slurmctld.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$run/slurmctld.pid")")
# A node of several: its network namespace (nsenter, which keeps this machine's /sys and so its
# cgroups), its own hostname and /tmp (PMIx keeps per-step directories there).
if [ "$node_count" -eq 1 ]; then
  mkdir -p "$run/spool.$host"
  $SUDO env SLURM_CONF="$SLURM_CONF" slurmd -f "$SLURM_CONF"
else
  for ((i = 0; i < node_count; i++)); do
    name=node$((i + 1))
    mkdir -p "$run/spool.$name"
    nsenter --net="/run/netns/${nodes[$i]}" unshare --uts --mount --propagation private \
      sh -c 'mount -t tmpfs tmpfs /tmp && hostname "$1" && exec slurmd -f "$SLURM_CONF" -N "$1"' node "$name"
  done
fi
for _ in $(seq 100); do
  [ "$(sinfo -h -N -o %T 2>/dev/null | grep -c idle)" -eq "$node_count" ] && break
  sleep 0.2
done
sinfo -h -N -o "%N %T %c %m" | sed 's/^/slurm test: node /'
[ "$(sinfo -h -N -o %T | grep -c idle)" -eq "$node_count" ] || {
  echo "FAIL: not every node became idle"; tail -n 20 "$run"/slurm*.log; exit 1; }

# 4. Every recipe in cluster/, unchanged: srun --mpi=pmix, mpirun inside the allocation, the
# multi-node job (on this one node: its resources overridden on the sbatch line), and a job array
# over two inputs. More tasks than CPUs need --overcommit (-O); mpirun then oversubscribes.
input=${2:-}
if [ -z "$input" ]; then
  "$partet" generate genus3 --faces 20000 -o "$run/jobs/genus3.off" > /dev/null
  input=$run/jobs/genus3.off
fi
input=$(realpath "$input")
if [ "$node_count" -gt 1 ]; then
  # A node's /tmp is its own, and the checkout (so the binary and a shared model) may be under
  # this machine's /tmp: the nodes get copies in the shared run directory.
  cp "$partet" "$run/partet"
  partet=$run/partet
  if [ "$input" != "$run/jobs/genus3.off" ]; then
    cp "$input" "$run/jobs/in-${input##*/}"
    input=$run/jobs/in-${input##*/}
  fi
fi
"$partet" generate torus --faces 6000 -o "$run/jobs/torus.off" > /dev/null
printf '%s\n' "$input" "$run/jobs/torus.off" > "$run/jobs/inputs.txt"
over=()
[ "$cpus" -ge 2 ] || over=(--overcommit)
export PARTET=$partet OMPI_MCA_rmaps_base_oversubscribe=1
[ "$(id -u)" -ne 0 ] || export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
submit() {  # NAME LOG SBATCH-OPTIONS... -- RECIPE ARGS...
  local name=$1 log=$2
  shift 2
  local options=()
  while [ "$1" != "--" ]; do options+=("$1"); shift; done
  shift
  local id
  id=$(sbatch --parsable "${over[@]}" --mem=2G --chdir="$run/jobs" --output="$run/jobs/$log" "${options[@]}" "$@")
  echo "slurm test: submitted $name as job $id"
  jobs+=("$id")
  job_names+=("$name")
}
jobs=() job_names=()
if [ "$node_count" -eq 1 ]; then
  submit srun slurm-srun.log -- "$project/cluster/slurm-srun.sbatch" "$input" "$run/jobs/srun/out"
  submit mpirun slurm-mpirun.log -- "$project/cluster/slurm-mpirun.sbatch" "$input" "$run/jobs/mpirun/out"
  submit multinode slurm-multinode.log --nodes=1 --ntasks-per-node=2 --time=10 \
    -- "$project/cluster/slurm-multinode.sbatch" "$input" "$run/jobs/multinode/out"
  submit array "slurm-array-%a.log" --array=1-2 -- "$project/cluster/slurm-array.sbatch" "$run/jobs/inputs.txt" "$run/jobs/array"
  logs="slurm-srun.log slurm-mpirun.log slurm-multinode.log slurm-array-1.log slurm-array-2.log"
else
  # Where a job's ranks run: one per node, each with the node's hostname and address.
  srun -N "$node_count" --ntasks-per-node=1 --mem=100M --chdir="$run/jobs" sh -c \
    'echo "$(hostname) $(ip -4 -o addr show scope global | awk "{print \$4}")"' | sort > "$run/where"
  sed 's/^/slurm test: a task on /' "$run/where"
  [ "$(cut -d' ' -f1 "$run/where" | sort -u | wc -l)" -eq "$node_count" ] &&
    [ "$(cut -d' ' -f2 "$run/where" | sort -u | wc -l)" -eq "$node_count" ] ||
    { echo "FAIL: the tasks did not run on $node_count hosts with their own addresses"; exit 1; }
  # A mistyped option under srun: every rank rejects it before MPI starts, and rank 0's message
  # must still come out (the other ranks wait for it) with the usage exit code.
  code=0
  srun -N "$node_count" --ntasks-per-node=1 --mpi=pmix --kill-on-bad-exit=1 --mem=100M --chdir="$run/jobs" \
    "$partet" mesh "$input" -o "$run/jobs/bad" --pieces 0 > "$run/usage.log" 2>&1 || code=$?
  grep -q -- "--pieces: Value 0 not in range" "$run/usage.log" && [ "$code" -ne 0 ] ||
    { echo "FAIL: a usage error under srun (exit $code) said:"; cat "$run/usage.log"; exit 1; }
  echo "slurm test: a usage error under srun on $node_count nodes: exit $code, $(grep -m1 -- --pieces "$run/usage.log")"
  spread=(--nodes="$node_count" --ntasks-per-node=1)
  submit srun slurm-srun.log "${spread[@]}" --ntasks="$node_count" \
    -- "$project/cluster/slurm-srun.sbatch" "$input" "$run/jobs/srun/out"
  submit mpirun slurm-mpirun.log "${spread[@]}" --ntasks="$node_count" \
    -- "$project/cluster/slurm-mpirun.sbatch" "$input" "$run/jobs/mpirun/out"
  # The XDMF set: every rank writes its block of the HDF5 files into the shared directory.
  submit multinode slurm-multinode.log "${spread[@]}" --time=10 \
    -- "$project/cluster/slurm-multinode.sbatch" "$input" "$run/jobs/multinode/out.xdmf"
  logs="slurm-srun.log slurm-mpirun.log slurm-multinode.log"
fi

# 5. Wait (at most 10 minutes), then judge each job by its log: it must end with a passed check.
deadline=$((SECONDS + 600))
while [ -n "$(squeue -h -j "$(IFS=,; echo "${jobs[*]}")" 2>/dev/null)" ]; do
  [ $SECONDS -lt $deadline ] || { echo "FAIL: jobs still queued or running after 600 s"; squeue; exit 1; }
  sleep 1
done
failed=0
for log in $logs; do
  echo "---- $log:"
  cat "$run/jobs/$log" 2>/dev/null || echo "(no log)"
  if tail -n 1 "$run/jobs/$log" 2>/dev/null | grep -q "check passed"; then
    echo "ok: ${log%.log}: $(tail -n 1 "$run/jobs/$log")"
  else
    echo "FAIL: ${log%.log} did not end with a passed check"
    failed=1
  fi
done
# The recipes keep their pieces (--checkpoint PREFIX.pieces) and remove them after the check.
left=0
for recipe in srun mpirun multinode; do
  if ! grep -q -- "--checkpoint" "$project/cluster/slurm-$recipe.sbatch"; then
    echo "FAIL: slurm-$recipe.sbatch keeps no checkpoint"; left=1
  elif [ -n "$(ls -d "$run/jobs/$recipe"/*.pieces 2> /dev/null)" ]; then
    echo "FAIL: slurm-$recipe: its checkpoint is still there after the check"; left=1
  fi
done
[ $left -eq 0 ] && echo "ok: the srun, mpirun and multinode recipes run with --checkpoint and left none after the check" || failed=1
# On several nodes the XDMF set is checked by all of the job's ranks, one per node.
if [ "$node_count" -gt 1 ]; then
  if grep -q "checked on $node_count ranks" "$run/jobs/slurm-multinode.log" 2>/dev/null; then
    echo "ok: slurm-multinode: the XDMF set checked on $node_count ranks, one per node"
  else
    echo "FAIL: slurm-multinode: the XDMF set was not checked on $node_count ranks"
    failed=1
  fi
fi
# On several nodes the files must be those one process writes (same pieces: 2 and 4 per rank).
if [ "$node_count" -gt 1 ] && [ $failed -eq 0 ]; then
  (cd "$run/jobs" && "$partet" mesh "$input" -o one --pieces $((2 * node_count)) --quiet &&
    "$partet" mesh "$input" -o many.xdmf --pieces $((4 * node_count)) --quiet)
  for pair in srun/out.node:one.node srun/out.ele:one.ele srun/out.neigh:one.neigh mpirun/out.ele:one.ele \
    multinode/out.h5:many.h5 multinode/out_boundary.h5:many_boundary.h5; do
    if cmp -s "$run/jobs/${pair%%:*}" "$run/jobs/${pair#*:}"; then
      echo "ok: ${pair%%:*} is byte-identical to 1 process's ${pair#*:}"
    else
      echo "FAIL: ${pair%%:*} differs from 1 process's ${pair#*:}"
      failed=1
    fi
  done
  # Each job ran on every node: node1 ran the batch script (and mpirun's or srun's rank 0), and
  # every other node's slurmd launched a task of the job's first step (a rank, or mpirun's daemon).
  for ((j = 0; j < ${#jobs[@]}; j++)); do
    grep -q "Launching batch job ${jobs[$j]} " "$run/slurmd.node1.log" ||
      { echo "FAIL: the ${job_names[$j]} job's script did not run on node1"; failed=1; }
    for ((i = 2; i <= node_count; i++)); do
      grep -q "launch task StepId=${jobs[$j]}\.0 " "$run/slurmd.node$i.log" ||
        { echo "FAIL: the ${job_names[$j]} job ran no task on node$i"; failed=1; }
    done
  done
  ranks=$(/usr/bin/python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['ranks'])" "$run/jobs/srun/out.report.json")
  [ "$ranks" -eq "$node_count" ] || { echo "FAIL: the srun job's report says $ranks ranks"; failed=1; }
fi
# 6. A job that Slurm suspends (scontrol suspend: SIGSTOP to all of its processes) for longer
# than every time limit, then resumes, goes on as if never stopped: the same files as a run
# outside Slurm, no retry, no warning. Piece 1's process sleeps 2 s first (a test hook), so that
# a piece is at work when the job is suspended; --piece-timeout 1 makes every limit (4 s for a
# piece's process, 14 s for a rank's answer) shorter than the 16 s pause.
if [ "$node_count" -eq 1 ] && [ $failed -eq 0 ]; then
  mkdir -p "$run/jobs/suspend"
  cd "$run/jobs/suspend"
  "$partet" mesh ../torus.off -o ref --pieces 6 --piece-timeout 1 --quiet
  id=$(PARTET_INJECT_FAILURE=1:stall PARTET_TEST_STALL_S=2 sbatch --parsable "${over[@]}" --ntasks=2 --mem=2G \
    --output="$run/jobs/slurm-suspend.log" --wrap "srun --mpi=pmix --kill-on-bad-exit=1 '$partet' mesh ../torus.off -o out --pieces 6 \
    --piece-timeout 1 --report out.json && '$partet' check ../torus.off out")
  # A TetGen process: a partet process whose parent is one (no other job runs now; a process's
  # name is its binary's, cut to 15 characters).
  meshing_child() {
    ps -e -o pid=,ppid=,comm= | awk -v name="$(basename "$partet" | cut -c1-15)" '{comm[$1] = $3; parent[$1] = $2}
      END {for (p in comm) if (comm[p] == name && comm[parent[p]] == name) found = 1; exit !found}'
  }
  for i in $(seq 600); do
    meshing_child && sleep 0.3 && meshing_child && break
    sleep 0.05
  done
  scontrol suspend "$id"
  state=$(squeue -h -j "$id" -o %T)
  sleep 16
  scontrol resume "$id"
  deadline=$((SECONDS + 120))
  while [ -n "$(squeue -h -j "$id" 2>/dev/null)" ] && [ $SECONDS -lt $deadline ]; do sleep 1; done
  echo "---- slurm-suspend.log:"
  cat "$run/jobs/slurm-suspend.log"
  problem=""
  [ "$state" = SUSPENDED ] || problem="the job was $state, not SUSPENDED, after scontrol suspend"
  tail -n 1 "$run/jobs/slurm-suspend.log" | grep -q "check passed" || problem=${problem:-"no passed check"}
  ! grep -qi warning "$run/jobs/slurm-suspend.log" || problem=${problem:-"it warned"}
  for ext in node ele face neigh; do
    cmp -s "ref.$ext" "out.$ext" || problem=${problem:-".$ext differs from a run outside Slurm"}
  done
  retries=$(/usr/bin/python3 -c "import json, sys; print(len(json.load(open(sys.argv[1]))['retries']))" out.json 2>/dev/null)
  [ "$retries" = 0 ] || problem=${problem:-"retries: $retries"}
  cd "$project"
  if [ -z "$problem" ]; then
    echo "ok: slurm-suspend: suspended 16 s mid-piece and resumed; the same files as a run outside Slurm, no retry"
  else
    echo "FAIL: slurm-suspend: $problem"
    failed=1
  fi
fi
# 7. The srun recipe as shipped (--requeue, --checkpoint PREFIX.pieces) requeued by Slurm while
# a piece is at work (scontrol requeue: the job is killed and queued again, as at a preemption):
# the rerun takes the 3 pieces the first run kept, meshes the fourth, and writes the files a run
# outside Slurm writes; the recipe removes the checkpoint once the check passed. Piece 3's process
# sleeps 6 s first (a test hook, in both runs), so the others are kept before the requeue.
if [ "$node_count" -eq 1 ] && [ $failed -eq 0 ]; then
  mkdir -p "$run/jobs/requeue"
  cd "$run/jobs/requeue"
  started=$SECONDS
  "$partet" mesh ../torus.off -o ref --pieces 4 --quiet
  id=$(PARTET_INJECT_FAILURE=3:stall PARTET_TEST_STALL_S=6 sbatch --parsable "${over[@]}" --ntasks=2 --mem=2G \
    --output="$run/jobs/slurm-requeue.log" "$project/cluster/slurm-srun.sbatch" ../torus.off out)
  kept() { [ "$(ls out.pieces 2> /dev/null | grep -c '^piece-.*\.bin$')" -ge 3 ]; }
  for i in $(seq 600); do kept && break; sleep 0.1; done
  kept_before=$(ls out.pieces 2> /dev/null | grep -c '^piece-.*\.bin$')
  scontrol requeue "$id"
  # Slurm makes a requeued job wait 2 minutes before it may start again; here it may at once.
  for i in $(seq 100); do [ "$(squeue -h -j "$id" -o %T)" = PENDING ] && break; sleep 0.1; done
  scontrol update JobId="$id" StartTime=now
  deadline=$((SECONDS + 180))
  while [ -n "$(squeue -h -j "$id" 2>/dev/null)" ] && [ $SECONDS -lt $deadline ]; do sleep 1; done
  echo "---- slurm-requeue.log:"
  cat "$run/jobs/slurm-requeue.log"
  problem=""
  [ "$kept_before" = 3 ] || problem="$kept_before pieces kept before the requeue, not 3"
  restarts=$(scontrol show job "$id" | grep -o "Restarts=[0-9]*")
  [ "$restarts" = Restarts=1 ] || problem=${problem:-"the job shows $restarts"}
  tail -n 1 "$run/jobs/slurm-requeue.log" | grep -q "check passed" || problem=${problem:-"no passed check"}
  taken=$(grep -c "taken from the checkpoint" "$run/jobs/slurm-requeue.log")
  [ "$taken" = 3 ] || problem=${problem:-"$taken pieces taken from the checkpoint, not 3"}
  for ext in node ele face neigh; do
    cmp -s "ref.$ext" "out.$ext" || problem=${problem:-".$ext differs from a run outside Slurm"}
  done
  [ ! -e out.pieces ] || problem=${problem:-"the checkpoint was not removed after the check"}
  cd "$project"
  if [ -z "$problem" ]; then
    echo "ok: slurm-requeue: requeued with 3 of 4 pieces kept; the rerun took them and wrote the files of a run outside Slurm ($((SECONDS - started)) s)"
  else
    echo "FAIL: slurm-requeue: $problem"
    failed=1
  fi
fi
if [ $failed -ne 0 ]; then
  echo "---- slurmctld log:"; tail -n 30 "$run/slurmctld.log"
  for log in "$run"/slurmd.*.log; do echo "---- $(basename "$log"):"; tail -n 30 "$log"; done
fi
exit $failed
