#!/usr/bin/python3
"""Reads partet's XDMF set the way a DOLFINx user does, in parallel under mpiexec: the mesh from
PREFIX.xdmf (XDMFFile.read_mesh) and the boundary markers from PREFIX_boundary.xdmf
(read_meshtags), then checks, summed over the ranks, the counts of tets and boundary facets and
the volume against partet's TetGen files of the same run. Usage: dolfinx_read.py PREFIX"""
import sys

import meshio
import numpy as np
import ufl
from dolfinx import fem, io
from dolfinx.mesh import exterior_facet_indices
from mpi4py import MPI

prefix = sys.argv[1]
comm = MPI.COMM_WORLD


def tetgen_figures():
    """Tets, boundary faces and volume from the TetGen files (rank 0 reads them)."""
    ref = meshio.read(prefix + ".node", file_format="tetgen")
    p, t = ref.points, ref.get_cells_type("tetra")
    a, b, c, d = (p[t[:, i]] for i in range(4))
    volume = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)).sum() / 6
    faces = int(open(prefix + ".face").readline().split()[0])
    return len(t), faces, volume


tets, faces, volume = comm.bcast(tetgen_figures() if comm.rank == 0 else None, root=0)
with io.XDMFFile(comm, prefix + ".xdmf", "r") as xdmf:
    mesh = xdmf.read_mesh(name="mesh")
mesh.topology.create_connectivity(2, 3)
with io.XDMFFile(comm, prefix + "_boundary.xdmf", "r") as xdmf:
    tags = xdmf.read_meshtags(mesh, name="boundary")

facet_map = mesh.topology.index_map(2)
owned = np.arange(facet_map.size_local)  # each facet counted on the rank that owns it
own_tets = comm.allreduce(mesh.topology.index_map(3).size_local, op=MPI.SUM)
tagged = comm.allreduce(len(np.intersect1d(tags.indices, owned)), op=MPI.SUM)
exterior = comm.allreduce(len(np.intersect1d(exterior_facet_indices(mesh.topology), owned)), op=MPI.SUM)
measured = comm.allreduce(fem.assemble_scalar(fem.form(fem.Constant(mesh, 1.0) * ufl.dx)), op=MPI.SUM)
markers = set(np.unique(np.concatenate(comm.allgather(tags.values))).tolist())

failures = []
if own_tets != tets: failures.append(f"{own_tets} tets read, {tets} written")
if tagged != faces: failures.append(f"{tagged} boundary facets tagged, {faces} written")
if exterior != faces: failures.append(f"{exterior} exterior facets in the mesh, {faces} boundary triangles written")
if abs(measured - volume) > 1e-9 * abs(volume): failures.append(f"volume {measured!r}, expected {volume!r}")
if markers != {1}: failures.append(f"markers {markers}")
if comm.rank == 0:
    print(f"dolfinx on {comm.size} ranks: {own_tets} tets, {tagged} tagged boundary facets, volume {measured:.12g}")
    for f in failures: print("FAIL:", f)
sys.exit(1 if failures else 0)
