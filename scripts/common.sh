# Shared by the scripts in scripts/: source it, don't run it.
#   here      the scripts/ directory        partet   the binary ($PARTET or build/partet)
#   work      a temporary directory, removed on exit (make_work_dir)
#   median    reads numbers, prints their median
#   timed     runs a command under GNU time: FILE gets "WALL_SECONDS PEAK_RSS_KB"
# As root, OpenMPI refuses to start without the two OMPI_ALLOW_* variables; they are set here.
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
partet=${PARTET:-$here/../build/partet}
if [ "$(id -u)" -eq 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi

make_work_dir() {
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
}

median() { sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }

# The one timing wrapper of the benchmark scripts: timed FILE COMMAND... (exported, so that
# commands run through xargs or sh -c can use it too).
timed() {
  local file=$1
  shift
  /usr/bin/time -f "%e %M" -o "$file" "$@"
}
export -f timed
