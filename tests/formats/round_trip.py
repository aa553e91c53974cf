#!/usr/bin/python3
"""Reads every format partet wrote at PREFIX with independent readers (meshio; the gmsh binary
for MSH; VTK for the .pvtu set) and compares it with partet's TetGen files of the same run: points bit for bit, tets in
order, boundary triangles, cell data. Usage: round_trip.py PREFIX PIECES REGIONS"""
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

import meshio
import numpy as np

prefix, pieces, regions = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
failures = []


def expect(condition, what):
    if not condition:
        failures.append(what)


ref = meshio.read(prefix + ".node", file_format="tetgen")
points, tets = ref.points, ref.get_cells_type("tetra")
# .face lines: index a b c [marker]; the boundary triangles in mesh numbering.
faces = np.array([[int(x) for x in line.split()[1:4]] for line in open(prefix + ".face").read().splitlines()[1:]
                  if line and not line.startswith("#")])
print(f"tetgen files: {len(points)} points, {len(tets)} tets, {len(faces)} boundary faces")


def volumes(p, t):
    a, b, c, d = (p[t[:, i]] for i in range(4))
    return np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))


expect((volumes(points, tets) > 0).all(), "TetGen files: a tet is not positively oriented")


def same_mesh(name, m, exact=True, with_faces=True):
    close = np.array_equal if exact else (lambda a, b: a.shape == b.shape and np.allclose(a, b, rtol=1e-15, atol=0))
    expect(close(m.points, points), f"{name}: points differ")
    expect(np.array_equal(m.get_cells_type("tetra"), tets), f"{name}: tets differ")
    if with_faces:
        expect(np.array_equal(m.get_cells_type("triangle"), faces), f"{name}: boundary triangles differ")
    print(f"{name}: {len(m.points)} points, {len(m.get_cells_type('tetra'))} tets, "
          f"{len(m.get_cells_type('triangle'))} triangles")


# VTU: cell data piece (-1 or a piece index) and region (1..regions).
vtu = meshio.read(prefix + ".vtu")
same_mesh("vtu", vtu, with_faces=False)
piece = np.concatenate(vtu.cell_data["piece"]).ravel()
region = np.concatenate(vtu.cell_data["region"]).ravel()
expect(piece.min() >= -1 and piece.max() < pieces, f"vtu: piece values {piece.min()}..{piece.max()}")
expect(sorted(set(region.tolist())) == list(range(1, regions + 1)), f"vtu: regions {sorted(set(region.tolist()))}")

# PVTU: the index names one .vtu per piece value; together they hold every tet once.
index = ET.parse(prefix + ".pvtu").getroot()
sources = [p.get("Source") for p in index.iter("Piece")]
directory = prefix.rsplit("/", 1)[0] + "/" if "/" in prefix else ""
key = {tuple(p): i for i, p in enumerate(points)}
seen = np.zeros(len(tets), dtype=int)
tet_index = {tuple(t): i for i, t in enumerate(tets)}
for source in sources:
    part = meshio.read(directory + source)
    values = set(np.concatenate(part.cell_data["piece"]).ravel().tolist())
    expect(len(values) == 1, f"pvtu: {source} mixes pieces {values}")
    to_global = np.array([key[tuple(p)] for p in part.points])
    expect(np.array_equal(part.point_data["GlobalPointIds"].ravel(), to_global),
           f"pvtu: {source}'s GlobalPointIds are not its points' ids in the whole mesh")
    for t in to_global[part.get_cells_type("tetra")]:
        seen[tet_index[tuple(t)]] += 1
expect((seen == 1).all(), f"pvtu: {np.sum(seen != 1)} tets not in exactly one piece file")
print(f"pvtu: {len(sources)} piece files, every tet in exactly one, GlobalPointIds as in the whole mesh")

# VTK itself (the reader ParaView uses) reads the set, and takes GlobalPointIds for its global ids.
import vtk
from vtk.util.numpy_support import vtk_to_numpy
reader = vtk.vtkXMLPUnstructuredGridReader()
reader.SetFileName(prefix + ".pvtu")
reader.Update()
grid = reader.GetOutput()
global_ids = grid.GetPointData().GetGlobalIds()
expect(grid.GetNumberOfCells() == len(tets), f"pvtu: VTK read {grid.GetNumberOfCells()} cells")
expect(global_ids is not None and np.array_equal(np.unique(vtk_to_numpy(global_ids)), np.arange(len(points))),
       "pvtu: VTK's global ids are not the mesh's points, each at least once")
print(f"pvtu: VTK {vtk.vtkVersion.GetVTKVersion()} reads {grid.GetNumberOfCells()} cells, global ids of "
      f"{len(points)} points")

# MSH 4.1, ASCII and binary: meshio, then gmsh itself (its checker, and the mesh it re-saves).
for name, path in (("msh", prefix + ".msh"), ("msh-binary", prefix + "_binary.msh")):
    m = meshio.read(path)
    same_mesh(name, m)
    physical = {c.type: set(np.asarray(d).ravel().tolist()) for c, d in zip(m.cells, m.cell_data["gmsh:physical"])}
    expect(physical == {"triangle": {2}, "tetra": {1}}, f"{name}: physical groups {physical}")
    out = subprocess.run(["gmsh", path, "-check"], capture_output=True, text=True)
    log = out.stdout + out.stderr
    counts = re.search(r"(\d+) nodes\s*\n.*?(\d+) elements", log)
    expect(out.returncode == 0 and counts is not None, f"{name}: gmsh -check failed:\n{log}")
    if counts:
        expect(int(counts.group(1)) == len(points) and int(counts.group(2)) == len(tets) + len(faces),
               f"{name}: gmsh read {counts.group(1)} nodes, {counts.group(2)} elements")
    resaved = path + ".gmsh.msh"
    subprocess.run(["gmsh", path, "-save", "-format", "msh41", "-o", resaved], capture_output=True, check=True)
    same_mesh(name + " re-saved by gmsh", meshio.read(resaved), exact=False)

# MEDIT: references: triangles 1, tets their region.
medit = meshio.read(prefix + ".mesh")
same_mesh("medit", medit)
refs = dict(zip([c.type for c in medit.cells], medit.cell_data["medit:ref"]))
expect(set(np.asarray(refs["triangle"]).ravel().tolist()) == {1}, "medit: triangle references")
expect(np.array_equal(np.asarray(refs["tetra"]).ravel(), region), "medit: tet references differ from the vtu regions")

# XDMF + HDF5: the tets (cell data region and piece as in the vtu) and, in _boundary.xdmf, the
# boundary triangles with marker 1; ids stored as 64-bit integers.
import os
if os.path.exists(prefix + ".xdmf"):
    import h5py
    x = meshio.read(prefix + ".xdmf")
    same_mesh("xdmf", x, with_faces=False)
    expect(np.array_equal(np.concatenate(x.cell_data["region"]).ravel(), region), "xdmf: regions differ from the vtu's")
    expect(np.array_equal(np.concatenate(x.cell_data["piece"]).ravel(), piece), "xdmf: pieces differ from the vtu's")
    b = meshio.read(prefix + "_boundary.xdmf")
    expect(np.array_equal(b.get_cells_type("triangle"), faces), "xdmf: boundary triangles differ")
    expect(set(np.concatenate(b.cell_data["boundary"]).ravel().tolist()) == {1}, "xdmf: boundary markers")
    for h5_path, name in ((prefix + ".h5", "Mesh/mesh/topology"), (prefix + "_boundary.h5", "MeshTags/boundary/topology")):
        with h5py.File(h5_path, "r") as h5:
            expect(h5[name].dtype == np.int64, f"xdmf: {name} is {h5[name].dtype}, not int64")
    print(f"xdmf: {len(x.points)} points, {len(x.get_cells_type('tetra'))} tets, "
          f"{len(b.get_cells_type('triangle'))} boundary triangles, int64 ids")

for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
