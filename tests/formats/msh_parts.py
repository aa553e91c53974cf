#!/usr/bin/python3
"""Reads the MSH partition sets partet wrote (PREFIX_1.msh ... PREFIX_N.msh) with gmsh itself and
compares them with the single .msh of the same run (which round_trip.py compares with the TetGen
files): gmsh reads every file alone and the whole set at once, and together the partitions hold
every tet and boundary triangle exactly once, each in the single file's physical group. The ASCII
set is also read here, to check that every node and element keeps the single file's tag and a
node's coordinates are the same bits in every file that has it.
Usage: msh_parts.py SINGLE.msh PARTITIONS ASCII_PREFIX [OTHER_PREFIX ...]"""
import os
import re
import subprocess
import sys
import tempfile

import meshio
import numpy as np

single, partitions, prefixes = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
failures = []


def expect(condition, what):
    if not condition:
        failures.append(what)


ref = meshio.read(single)
points, tets, triangles = ref.points, ref.get_cells_type("tetra"), ref.get_cells_type("triangle")


def as_reference_ids(p):
    """Each point's index in the single file, by nearest coordinates (gmsh's MSH 2 text has fewer
    than 17 digits); fails when one is not within 1e-12 of it."""
    ids = np.empty(len(p), dtype=int)
    for first in range(0, len(p), 256):
        d = np.linalg.norm(p[first:first + 256, None, :] - points[None, :, :], axis=2)
        ids[first:first + 256] = d.argmin(axis=1)
        expect(d.min(axis=1).max() < 1e-12, "a point is not one of the single file's")
    return ids


def by_points(ids, m, cell_type):
    """Each cell of a type as the sorted tuple of its points' single-file ids, and its physical
    group."""
    found = []
    for c, physical in zip(m.cells, m.cell_data["gmsh:physical"]):
        if c.type == cell_type:
            found += [(tuple(sorted(ids[cell])), int(g)) for cell, g in zip(c.data, np.asarray(physical).ravel())]
    return sorted(found)


identity = np.arange(len(points))
ref_tets, ref_triangles = by_points(identity, ref, "tetra"), by_points(identity, ref, "triangle")


def files_of(prefix):
    directory, base = os.path.split(prefix)
    pattern = re.compile(re.escape(base) + r"_([1-9][0-9]*)\.msh$")
    found = sorted((int(m.group(1)), name) for name in os.listdir(directory or ".") if (m := pattern.match(name)))
    return [os.path.join(directory, name) for _, name in found], [i for i, _ in found]


def gmsh(*args):
    out = subprocess.run(["gmsh", *args], capture_output=True, text=True)
    return out.returncode, out.stdout + out.stderr


def check_with_gmsh(prefix, files):
    for path in files:
        code, log = gmsh(path, "-check")
        complaints = [line for line in log.splitlines() if line.startswith(("Warning", "Error"))]
        expect(code == 0 and not complaints, f"{path}: gmsh -check: {complaints or log}")
        expect(f"{partitions} partitions" in log, f"{path}: gmsh did not read {partitions} partitions")
    # The whole set in one gmsh session, saved without partitions for meshio.
    with tempfile.TemporaryDirectory() as work:
        merged = os.path.join(work, "merged.msh")
        code, log = gmsh(*files, "-save", "-format", "msh2", "-o", merged)
        expect(code == 0, f"{prefix}: gmsh could not open the set together:\n{log}")
        m = meshio.read(merged)
    ids = as_reference_ids(m.points)
    expect(by_points(ids, m, "tetra") == ref_tets, f"{prefix}: the tets or their physical groups differ")
    expect(by_points(ids, m, "triangle") == ref_triangles,
           f"{prefix}: the boundary triangles or their physical groups differ")
    print(f"{os.path.basename(prefix)}: {len(files)} files; gmsh reads each and all together: "
          f"{len(m.get_cells_type('tetra'))} tets, {len(m.get_cells_type('triangle'))} boundary triangles")


def sections(path):
    """An ASCII MSH file's sections: name -> list of lines."""
    result, name = {}, None
    for line in open(path).read().splitlines():
        if line.startswith("$End"):
            name = None
        elif line.startswith("$"):
            name = line[1:]
            result[name] = []
        elif name:
            result[name].append(line.split())
    return result


def check_tags(files):
    seen_tets = np.zeros(len(tets), dtype=int)
    seen_triangles = np.zeros(len(triangles), dtype=int)
    for path in files:
        s = sections(path)
        expect(int(s["PartitionedEntities"][0][0]) == partitions, f"{path}: numPartitions")
        nodes = s["Nodes"]
        blocks, rows = int(nodes[0][0]), 1
        for _ in range(blocks):
            count = int(nodes[rows][3])
            tags = [int(r[0]) for r in nodes[rows + 1:rows + 1 + count]]
            xyz = np.array([[float(x) for x in r] for r in nodes[rows + 1 + count:rows + 1 + 2 * count]])
            expect(np.array_equal(xyz, points[np.array(tags) - 1]), f"{path}: a node's coordinates differ")
            rows += 1 + 2 * count
        elements = s["Elements"]
        blocks, rows = int(elements[0][0]), 1
        for _ in range(blocks):
            kind, count = int(elements[rows][2]), int(elements[rows][3])
            for r in elements[rows + 1:rows + 1 + count]:
                tag, nodes_of = int(r[0]), np.array([int(x) - 1 for x in r[1:]])
                if kind == 4:  # tet: tags after the boundary triangles', as in the single file
                    t = tag - 1 - len(triangles)
                    expect(np.array_equal(tets[t], nodes_of), f"{path}: tet {tag} differs")
                    seen_tets[t] += 1
                else:
                    expect(np.array_equal(triangles[tag - 1], nodes_of), f"{path}: triangle {tag} differs")
                    seen_triangles[tag - 1] += 1
            rows += 1 + count
    expect((seen_tets == 1).all(), f"{np.sum(seen_tets != 1)} tets not in exactly one partition")
    expect((seen_triangles == 1).all(), f"{np.sum(seen_triangles != 1)} triangles not in exactly one partition")
    print(f"{len(files)} ASCII files: every node and element has the single file's tag; "
          "every tet and triangle in exactly one")


for i, prefix in enumerate(prefixes):
    files, numbers = files_of(prefix)
    expect(numbers == list(range(1, partitions + 1)), f"{prefix}: partition files {numbers}")
    check_with_gmsh(prefix, files)
    if i == 0:
        check_tags(files)

for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
