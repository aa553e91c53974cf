#!/usr/bin/python3
"""Two `partet check --json` results of the same mesh agree: both pass, and the same vertices,
tets, boundary faces and V-E+F-T; volumes to 1e-12 (ranks sum them in another order).
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
print(f"ok: {name}: {other['vertices']} vertices, {other['tets']} tets, {other['boundary_faces']} boundary faces, "
      f"as {reference_name}")
