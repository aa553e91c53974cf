# Sourced by the tests of runs that must not notice what happened to them (starved_piece.sh,
# suspended_job.sh). unchanged_run DIR REF RUN: RUN's TetGen files are REF's byte for byte, its
# report (DIR/RUN.json) lists no retry, and its log (DIR/log) no warning; else it says what
# differs, and returns 1.
unchanged_run() {
  local dir=$1 ref=$2 run=$3 ext retries
  for ext in node ele face neigh; do
    cmp -s "$dir/$ref.$ext" "$dir/$run.$ext" || { echo "$run: .$ext differs from $ref's"; return 1; }
  done
  retries=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["retries"]))' "$dir/$run.json")
  [ "$retries" = 0 ] || { echo "$run: $retries retries"; return 1; }
  ! grep -qi "warning" "$dir/log" || { echo "$run: warned"; return 1; }
}
