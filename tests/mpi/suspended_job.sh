#!/usr/bin/env bash
# A job suspended as a whole and resumed (Slurm's suspend and gang scheduling send SIGSTOP to all
# of its processes, SIGCONT later) goes on as if nothing happened: the pause does not count
# against any time limit, so no rank is taken for dead and no piece for stalled. Here every
# process of the job (mpiexec, the ranks, their TetGen processes) is stopped for 16 s while
# piece 1's process is in the middle of its work (PARTET_INJECT_FAILURE=1:stall keeps it there
# for 2 s), longer than both a piece's wall time limit (4 s with --piece-timeout 1) and the time
# rank 0 waits for a worker's answer (that plus 10 s). The job must succeed with the same files as
# a run that was never stopped, without a retry or a warning.
# Usage: suspended_job.sh PARTET MPIEXEC RANKS
set -uo pipefail
. "$(dirname "$0")/unchanged_run.sh"
partet=$1 mpiexec=$2 ranks=$3
work=$(mktemp -d)
session=""
trap '[ -z "$session" ] || pkill -CONT -s "$session" 2> /dev/null; rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; cat "$work/log" 2> /dev/null; exit 1; }
"$partet" generate torus --faces 6000 -o "$work/torus.off" > /dev/null || exit 1
export PARTET_INJECT_FAILURE=1:stall PARTET_TEST_STALL_S=2
mesh() {
  timeout 180 "$mpiexec" -n "$ranks" --oversubscribe -x PARTET_INJECT_FAILURE -x PARTET_TEST_STALL_S "$partet" mesh \
    "$work/torus.off" -o "$work/$1" --pieces 6 --piece-timeout 1 --report "$work/$1.json" > "$work/log" 2>&1
}
mesh ref || fail "the run that was never stopped failed"

# The job in a session of its own, so that all of its processes can be stopped at once.
setsid bash -c "$(declare -f mesh); work='$work' partet='$partet' mpiexec='$mpiexec' ranks='$ranks' mesh suspended" &
launcher=$!
session=$launcher
# Stop the job once piece 1 is in its stall, as a scheduler could at any moment: a rank's TetGen
# process (a partet process whose parent is one; a process's name is its binary's, cut to 15
# characters) that lives longer than a small piece takes.
meshing_child() {
  ps -o pid=,ppid=,comm= -s "$session" | awk -v name="$(basename "$partet" | cut -c1-15)" \
    '{comm[$1] = $3; parent[$1] = $2}
    END {for (p in comm) if (comm[p] == name && comm[parent[p]] == name) found = 1; exit !found}'
}
for i in $(seq 300); do
  meshing_child && sleep 0.3 && meshing_child && break
  sleep 0.05
done
pkill -STOP -s "$session"
stopped=$(pgrep -s "$session" | wc -l)
sleep 16
pkill -CONT -s "$session"
wait "$launcher"
code=$?
session=""
[ "$code" -ne 124 ] || fail "the job hung (killed after 180 s)"
[ "$code" -eq 0 ] || fail "exit code $code after a pause of 16 s"
problem=$(unchanged_run "$work" ref suspended) || fail "$problem (ref: the run never stopped)"
rank=$(python3 -c 'import json,sys; print([p["rank"] for p in json.load(open(sys.argv[1]))["piece"] if p["index"] == 1][0])' \
  "$work/suspended.json")
echo "ok: $stopped processes stopped for 16 s (piece 1 on rank $rank) and resumed; the same files as the run never" \
  "stopped, no retry"
