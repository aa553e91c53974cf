# Shared by the shell tests (source it after `set -uo pipefail`): a work directory, removed at exit
# with every process whose command line names it; ok/bad counters and the summary; waits.
work=$(mktemp -d)
trap 'pkill -KILL -f "$work/" 2> /dev/null; rm -rf "$work"' EXIT
pass=0 fail=0
ok() { pass=$((pass + 1)); echo "ok   $*"; }
bad() { fail=$((fail + 1)); echo "FAIL $*"; }
# Prints the counts; fails when a check failed.
summary() {
  echo "$pass passed, $fail failed"
  [ $fail = 0 ]
}
# Runs CONDITION (a command) every 0.1 s until it holds (0), the background job $pid ends or
# SECONDS pass (1).
wait_while_running() {
  local seconds=$1
  shift
  for _ in $(seq $((seconds * 10))); do
    "$@" && return 0
    kill -0 "$pid" 2> /dev/null || return 1
    sleep 0.1
  done
  return 1
}
# Waits (SECONDS at most) until no process whose command line holds PATTERN runs.
wait_gone() {
  for _ in $(seq $(($1 * 10))); do
    pgrep -f "$2" > /dev/null || return 0
    sleep 0.1
  done
  return 1
}
