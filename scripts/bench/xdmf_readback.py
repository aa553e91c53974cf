#!/usr/bin/python3
"""Reads a large run's XDMF set back with meshio (an independent reader: XDMF 3 through h5py)
and compares it with the TetGen files of the same run, also read by meshio: the same points bit
for bit and the same tets in the same order. For runs too large for the format tests
(tests/formats/round_trip.py does this and more on small meshes). Prints the counts and the
read times; exit 1 when they differ.
Usage: xdmf_readback.py PREFIX   (PREFIX.xdmf and PREFIX.node/.ele from one `partet mesh` run)"""
import sys
import time

import meshio
import numpy as np

prefix = sys.argv[1]
start = time.time()
xdmf = meshio.read(prefix + ".xdmf")
xdmf_seconds = time.time() - start
start = time.time()
tetgen = meshio.read(prefix + ".node", file_format="tetgen")
tetgen_seconds = time.time() - start

points_same = np.array_equal(xdmf.points, tetgen.points)
tets_x, tets_t = xdmf.get_cells_type("tetra"), tetgen.get_cells_type("tetra")
tets_same = np.array_equal(tets_x, tets_t)
print(f"xdmf (meshio {meshio.__version__}, {xdmf_seconds:.1f} s): {len(xdmf.points):,} points, "
      f"{len(tets_x):,} tets, connectivity {tets_x.dtype}")
print(f"tetgen files ({tetgen_seconds:.1f} s): {len(tetgen.points):,} points, {len(tets_t):,} tets")
print(f"points {'identical' if points_same else 'DIFFER'}; tets {'identical' if tets_same else 'DIFFER'}")
sys.exit(0 if points_same and tets_same else 1)
