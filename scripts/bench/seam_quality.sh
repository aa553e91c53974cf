#!/usr/bin/env bash
# Seam quality against TetGen, in the same run: for each input, `tetgen -p[q<Q>]YQ` once, then
# `partet mesh --check --report` for every K with the default switches (with -q: healed and
# polished; without: the cut vertices removed, cap points kept) and, with -H, also --no-heal and
# --heal. Prints, per run, tets, Steiner points (output vertices that are not input vertices), AMIPS avg/max, min
# dihedral, ratios to TetGen, the seam zone's AMIPS avg (tets touching a cut plane) against the
# same zone of TetGen's mesh (and the rest against the rest), the seam zone's worst tet, and the
# shares of the run spent healing and polishing. Tets crossing a plane are larger than average,
# so the fair baseline for a seam is TetGen's own mesh at the same place, not partet's mesh elsewhere.
# Figures, not a test: time it on a quiet machine.
#
# Usage: seam_quality.sh [-n RANKS] [-k "K ..."] [-q QUALITY] [-H] [-x "ARGS"] INPUT...
#   -n  MPI ranks (default 2; 1 runs without mpirun)   -k  piece counts (default "2 4 8")
#   -q  radius-edge bound for both (default none)      -H  also run --no-heal and --heal
#   -x  more partet mesh arguments (e.g. "--density 0")
set -euo pipefail
source "$(dirname "$0")/../common.sh"
ranks=2 ks="2 4 8" quality="" also_unhealed=0 extra=""
while getopts "n:k:q:Hx:" opt; do
  case $opt in
    n) ranks=$OPTARG ;; k) ks=$OPTARG ;; q) quality=$OPTARG ;; H) also_unhealed=1 ;; x) extra=$OPTARG ;;
    *) sed -n '2,16p' "$0"; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[ $# -ge 1 ] || { sed -n '2,16p' "$0"; exit 2; }
make_work_dir
launch=()
[ "$ranks" -gt 1 ] && launch=(mpirun -np "$ranks")
tg_switches="-pYQ" partet_quality=()
if [ -n "$quality" ]; then tg_switches="-pq${quality}YQ"; partet_quality=(--quality "$quality"); fi

cat > "$work/row.py" <<'PY'
import json, sys
label, check, report, input_vertices, tetgen, tg_zones = sys.argv[1:7]
c = json.load(open(check))
q = c["quality"]
cols = [label, c["tets"], c["vertices"] - int(input_vertices), "%.4f" % q["amips_avg"], "%.2f" % q["amips_max"],
        "%.3f" % q["min_dihedral_deg"]]
if tetgen != "-":
    t = json.load(open(tetgen))
    tq = t["quality"]
    cols += ["%.3f" % (c["tets"] / t["tets"]), "%.4f" % (q["amips_avg"] / tq["amips_avg"]),
             "%.3f" % (q["amips_max"] / tq["amips_max"]), "%.3f" % (q["min_dihedral_deg"] / tq["min_dihedral_deg"])]
    r, z = json.load(open(report)), json.load(open(tg_zones))
    seam, rest = r["quality"]["seam_zone"], r["quality"]["elsewhere"]
    tg_seam, tg_rest = z["seam_zone_quality"], z["elsewhere_quality"]
    cols += ["%.4f" % seam["amips_avg"], "%.4f" % tg_seam["amips_avg"],
             "%+.2f%%" % (100 * (seam["amips_avg"] / tg_seam["amips_avg"] - 1)),
             "%+.2f%%" % (100 * (rest["amips_avg"] / tg_rest["amips_avg"] - 1)),
             "%.3f" % seam["min_dihedral_deg"], "%.2f" % seam["amips_max"],
             "%.1f%%" % (100 * r["stage_seconds"].get("seam_healing", 0) / r["total_seconds"]),
             "%.1f%%" % (100 * r["stage_seconds"].get("polish", 0) / r["total_seconds"]),
             "%.2f" % r["total_seconds"]]
print(("%-28s" + " %9s" * (len(cols) - 1)) % tuple(cols))
PY
# One table row: label check.json report.json|- input_vertices tetgen.json|- tg_zones.json|-
# (tg_zones.json: TetGen's mesh checked against the planes of partet's report).
row() { /usr/bin/python3 "$work/row.py" "$@"; }

printf "%-28s" run
printf " %9s" tets steiner amips_avg amips_max min_dih tets/tg avg/tg max/tg dih/tg seam_avg tg_seam seam/tg \
  rest/tg seam_dih seam_max heal polish wall_s
echo
for input in "$@"; do
  name=$(basename "$input" .off)
  cp "$input" "$work/$name.off"
  (cd "$work" && tetgen $tg_switches "$name.off" > /dev/null)
  "$partet" check --json "$work/$name.off" "$work/$name.1" > "$work/tg.json" || true
  input_vertices=$(awk 'NR==2 {print $1; exit}' "$work/$name.off")
  row "$name tetgen $tg_switches" "$work/tg.json" - "$input_vertices" - -
  heal_modes=(default)
  [ "$also_unhealed" -eq 1 ] && heal_modes+=(no-heal heal)
  for k in $ks; do
    for mode in "${heal_modes[@]}"; do
      switches=("${partet_quality[@]}")
      [ "$mode" = default ] || switches+=(--$mode)
      # shellcheck disable=SC2206
      [ -n "$extra" ] && switches+=($extra)
      "${launch[@]}" "$partet" mesh "$work/$name.off" -o "$work/out" --pieces "$k" "${switches[@]}" \
        --check --report "$work/r.json" --quiet
      "$partet" check --json "$work/$name.off" "$work/out" > "$work/c.json"
      "$partet" check --json --report "$work/r.json" "$work/$name.off" "$work/$name.1" > "$work/tgz.json" || true
      row "$name K=$k $mode" "$work/c.json" "$work/r.json" "$input_vertices" "$work/tg.json" "$work/tgz.json"
    done
  done
done
