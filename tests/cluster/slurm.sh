#!/usr/bin/env bash
# A real single-node Slurm, started by hand: installs Debian's slurmctld, slurmd, slurm-client and
# munge if missing, writes a private configuration (this machine's CPUs and memory, non-default
# ports, all state in a temporary directory), starts munged, slurmctld and slurmd, submits every
# sbatch recipe in cluster/ (unchanged but for its arguments) on INPUT, waits for them, prints
# each job's log (ending with its `partet check` result) and stops the daemons by PID, also on
# failure.
# Usage: tests/cluster/slurm.sh PARTET [INPUT]   (INPUT default: a generated genus-3 surface)
set -euo pipefail
partet=$(realpath "${1:?partet binary}")
project=$(cd "$(dirname "$0")/../.." && pwd)
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"

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

# 2. A private configuration. Everything lives in $run; the daemons' PIDs are kept to stop them.
run=$(mktemp -d /tmp/partet-slurm.XXXXXX)
chmod 755 "$run"
pids=()
stop_daemons() {
  for pid in "${pids[@]}"; do $SUDO kill "$pid" 2>/dev/null || true; done
  sleep 1
  for pid in "${pids[@]}"; do $SUDO kill -9 "$pid" 2>/dev/null || true; done
  rm -rf "$run"
}
trap stop_daemons EXIT
user=$(id -un)
host=$(hostname -s)
cpus=$(nproc)
mem_mb=$(awk '/MemTotal/ { printf "%d", $2 / 1024 * 0.9 }' /proc/meminfo)
port=$((20000 + RANDOM % 20000))
mkdir -p "$run/state" "$run/spool" "$run/jobs"
cat > "$run/slurm.conf" <<CONF
ClusterName=partet-test
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=$user
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$run/munge.socket
CredType=cred/munge
StateSaveLocation=$run/state
SlurmdSpoolDir=$run/spool
SlurmctldPidFile=$run/slurmctld.pid
SlurmdPidFile=$run/slurmd.pid
SlurmctldLogFile=$run/slurmctld.log
SlurmdLogFile=$run/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
MpiDefault=none
ReturnToService=2
SchedulerType=sched/builtin
NodeName=$host CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=60 State=UP
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
$SUDO env SLURM_CONF="$SLURM_CONF" slurmd -f "$SLURM_CONF"
for _ in $(seq 50); do [ -s "$run/slurmd.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$run/slurmd.pid")")
for _ in $(seq 100); do
  sinfo -h -o %T 2>/dev/null | grep -q idle && break
  sleep 0.2
done
sinfo -h -o "%P %D %T %c %m" | sed 's/^/slurm test: node /'
sinfo -h -o %T | grep -q idle || { echo "FAIL: the node never became idle"; cat "$run"/slurm*.log; exit 1; }

# 4. Every recipe in cluster/, unchanged: srun --mpi=pmix, mpirun inside the allocation, the
# multi-node job (on this one node: its resources overridden on the sbatch line), and a job array
# over two inputs. More tasks than CPUs need --overcommit (-O); mpirun then oversubscribes.
input=${2:-}
if [ -z "$input" ]; then
  "$partet" generate genus3 --faces 20000 -o "$run/jobs/genus3.off" > /dev/null
  input=$run/jobs/genus3.off
fi
input=$(realpath "$input")
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
}
jobs=()
submit srun slurm-srun.log -- "$project/cluster/slurm-srun.sbatch" "$input" "$run/jobs/srun/out"
submit mpirun slurm-mpirun.log -- "$project/cluster/slurm-mpirun.sbatch" "$input" "$run/jobs/mpirun/out"
submit multinode slurm-multinode.log --nodes=1 --ntasks-per-node=2 --time=10 \
  -- "$project/cluster/slurm-multinode.sbatch" "$input" "$run/jobs/multinode/out"
submit array "slurm-array-%a.log" --array=1-2 -- "$project/cluster/slurm-array.sbatch" "$run/jobs/inputs.txt" "$run/jobs/array"

# 5. Wait (at most 10 minutes), then judge each job by its log: it must end with a passed check.
deadline=$((SECONDS + 600))
while [ -n "$(squeue -h -j "$(IFS=,; echo "${jobs[*]}")" 2>/dev/null)" ]; do
  [ $SECONDS -lt $deadline ] || { echo "FAIL: jobs still queued or running after 600 s"; squeue; exit 1; }
  sleep 1
done
failed=0
for log in slurm-srun.log slurm-mpirun.log slurm-multinode.log slurm-array-1.log slurm-array-2.log; do
  echo "---- $log:"
  cat "$run/jobs/$log" 2>/dev/null || echo "(no log)"
  if tail -n 1 "$run/jobs/$log" 2>/dev/null | grep -q "check passed"; then
    echo "ok: ${log%.log}: $(tail -n 1 "$run/jobs/$log")"
  else
    echo "FAIL: ${log%.log} did not end with a passed check"
    failed=1
  fi
done
if [ $failed -ne 0 ]; then
  echo "---- slurmctld log:"; tail -n 30 "$run/slurmctld.log"
  echo "---- slurmd log:"; tail -n 30 "$run/slurmd.log"
fi
exit $failed
