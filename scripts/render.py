#!/usr/bin/python3
"""Renders a partet result headless to a PNG: the tets on one side of a plane through the
middle, so the inside and the seams show, coloured by the piece that meshed them (grey: tets
re-meshed around the cuts).

Usage: scripts/render.py MESH.vtu OUT.png [--cut x|y|z] [--keep below|above] [--view ELEV AZIM]
MESH.vtu is written by `partet mesh ... --format vtu` (its cell data "piece" gives the colours).
Needs python3-meshio and python3-matplotlib (Debian)."""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import meshio
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("mesh")
parser.add_argument("png")
parser.add_argument("--cut", choices="xyz",
                    help="normal of the cutting plane (default: the shortest axis across the pieces' planes, so "
                         "every piece and seam is cut open)")
parser.add_argument("--keep", default="below", choices=["below", "above"])
parser.add_argument("--view", nargs=2, type=float, metavar=("ELEV", "AZIM"),
                    help="camera elevation and azimuth, degrees (default: facing the cut, slightly from above)")
args = parser.parse_args()

mesh = meshio.read(args.mesh)
points, tets = mesh.points, mesh.get_cells_type("tetra")
piece = np.concatenate(mesh.cell_data["piece"]).ravel()
centroid = points[tets].mean(axis=1)
extent = points.max(axis=0) - points.min(axis=0)
if args.cut:
    axis = "xyz".index(args.cut)
else:
    # The pieces are stacked along the axis their index follows best; cut along another one.
    pieces_at = piece >= 0
    follow = [abs(np.corrcoef(centroid[pieces_at, a], piece[pieces_at])[0, 1]) if extent[a] > 0 else 0 for a in range(3)]
    stacking = int(np.nanargmax(follow))
    axis = min((a for a in range(3) if a != stacking), key=lambda a: extent[a])  # the largest cut face
middle = 0.5 * (points[:, axis].min() + points[:, axis].max())
kept = centroid[:, axis] < middle if args.keep == "below" else centroid[:, axis] > middle

# The faces of the kept tets that no other kept tet shares: the cut-open solid's skin.
faces = np.concatenate([tets[kept][:, [1, 2, 3]], tets[kept][:, [0, 3, 2]], tets[kept][:, [0, 1, 3]],
                        tets[kept][:, [0, 2, 1]]])
owner = np.tile(piece[kept], 4)
key = np.sort(faces, axis=1)
_, first, count = np.unique(key, axis=0, return_index=True, return_counts=True)
skin = first[count == 1]
faces, owner = faces[skin], owner[skin]

palette = plt.get_cmap("tab10")
colour = np.array([(0.55, 0.55, 0.55, 1.0) if p < 0 else palette(p % 10) for p in owner])
triangles = points[faces]
normal = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-300
light = np.array([0.4, -0.6, 0.7])
light /= np.linalg.norm(light)
shade = 0.45 + 0.55 * np.abs(normal @ light)
colour[:, :3] *= shade[:, None]

figure = plt.figure(figsize=(8, 8), dpi=120)
ax = figure.add_subplot(projection="3d")
ax.add_collection3d(Poly3DCollection(triangles, facecolors=colour, edgecolors=(0, 0, 0, 0.15), linewidths=0.1))
low, high = points.min(axis=0), points.max(axis=0)
centre, radius = (low + high) / 2, 0.42 * (high - low).max()
ax.set_box_aspect((1, 1, 1))
for set_limits, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
    set_limits(c - radius, c + radius)
if args.view:
    ax.view_init(*args.view)
else:  # face the cut: the camera on the removed side
    sign = 1 if args.keep == "below" else -1
    ax.view_init(*{0: (15, 0 if sign > 0 else 180), 1: (15, 90 if sign > 0 else -90), 2: (80 * sign, -90)}[axis])
ax.set_axis_off()
pieces = sorted(set(piece.tolist()))
ax.set_title(f"{len(tets):,} tets in {sum(p >= 0 for p in pieces)} pieces, cut open at {'xyz'[axis]} = {middle:.3g}"
             + (" (grey: re-meshed seams)" if -1 in pieces else ""))
figure.savefig(args.png, bbox_inches="tight")
print(f"wrote {args.png}: {len(faces):,} faces shown")
