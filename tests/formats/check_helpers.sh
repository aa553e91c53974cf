# Shared by the tests of partet check on the output formats (sourced; needs $tests, the tests
# directory, and serial.json, the check of the run's TetGen files, in the working directory).

# The check result JSON agrees with the TetGen files' check (vertices, tets, boundary, volume, V-E+F-T).
same_as_tetgen_files() { "$tests/same_check.py" serial.json "$1" "$2" "the TetGen files"; }  # JSON NAME

# A check that must fail: COMMAND... must exit non-zero and say EXPECTED.
fails() {  # NAME EXPECTED COMMAND...
  local name=$1 expected=$2
  shift 2
  if "$@" > out 2>&1; then echo "FAIL: $name passed the check"; cat out; exit 1; fi
  grep -q "$expected" out || { echo "FAIL: $name: no '$expected':"; cat out; exit 1; }
  echo "ok: $name: $(grep -m 2 "VIOLATION\|error" out | tr '\n' ' ')"
}
