#!/usr/bin/python3
"""Two `partet check --json` results of the same mesh agree: both pass, and the same vertices,
tets, boundary faces, V-E+F-T and quality figures; volumes and averages to 1e-12 (ranks sum them
in another order).
Usage: same_check.py REFERENCE.json OTHER.json "WHAT OTHER IS" "WHAT THE REFERENCE IS"
"""
import json
import sys

reference, other = (json.load(open(path)) for path in sys.argv[1:3])
name, reference_name = sys.argv[3], sys.argv[4]
assert other["ok"] and reference["ok"], other["violations"] + reference["violations"]
for key in ("vertices", "tets", "boundary_faces", "euler_mesh", "euler_expected"):
    assert other[key] == reference[key], f"{key}: {other[key]} from {name}, {reference[key]} from {reference_name}"
for key in ("tet_volume", "surface_volume"):
    assert abs(other[key] - reference[key]) <= 1e-12 * abs(reference[key]), f"{key}: {other[key]} vs {reference[key]}"
# The quality figures (a check on several ranks finds them too): the same, averages to 1e-12.
q, r = other["quality"], reference["quality"]
for key in r:
    if key.endswith("_avg"):
        assert abs(q[key] - r[key]) <= 1e-12 * abs(r[key]), f"quality {key}: {q[key]} from {name}, {r[key]}"
    else:
        assert q[key] == r[key], f"quality {key}: {q[key]} from {name}, {r[key]} from {reference_name}"
print(f"ok: {name}: {other['vertices']} vertices, {other['tets']} tets, {other['boundary_faces']} boundary faces, "
      f"quality (AMIPS avg {q['amips_avg']:.6g} p99 {q['amips_p99']:.6g} max {q['amips_max']:.6g}), as {reference_name}")
