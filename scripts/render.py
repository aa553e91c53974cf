#!/usr/bin/python3
"""Renders a partet result headless to a PNG: the tets on one side of a plane through the
middle, edges drawn, so the inside and the seams show, coloured by the piece that meshed them
(grey: tets re-meshed around the cuts), with the other half's surface faint around them; seen
obliquely from the open side and framed to fill the picture.

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
                    help="camera elevation and azimuth, degrees, the cut's normal pointing up (default 32 -58)")
args = parser.parse_args()

mesh = meshio.read(args.mesh)
points, tets = mesh.points, mesh.get_cells_type("tetra")
piece = np.concatenate(mesh.cell_data["piece"]).ravel()
# A right-handed frame whose third axis is the cut's normal: with --cut a coordinate axis, else
# the object's own axes (PCA), so a tilted part lies flat and the cut shows its largest section.
if args.cut:
    normal_axis = "xyz".index(args.cut)
    frame = np.eye(3)[[(normal_axis + 1) % 3, (normal_axis + 2) % 3, normal_axis]]
else:
    _, vectors = np.linalg.eigh(np.cov((points - points.mean(axis=0)).T))
    axes = vectors.T[::-1]  # longest first
    tet_centres = points[tets].mean(axis=1) @ axes.T
    # The pieces are stacked along the axis their index follows best; cut across another one.
    pieces_at = piece >= 0
    follow = [abs(np.corrcoef(tet_centres[pieces_at, a], piece[pieces_at])[0, 1]) if pieces_at.sum() > 1 else 0
              for a in range(3)]
    stacking = int(np.nanargmax(follow)) if np.isfinite(follow).any() else 0
    extent = tet_centres.max(axis=0) - tet_centres.min(axis=0)
    normal_axis = min((a for a in range(3) if a != stacking), key=lambda a: extent[a])
    first = [a for a in range(3) if a != normal_axis]
    frame = np.array([axes[first[0]], axes[first[1]], np.cross(axes[first[0]], axes[first[1]])])
if args.keep == "above":  # look from the other side: turn the frame half a turn
    frame = frame * np.array([1.0, -1.0, -1.0])[:, None]
view_points = (points - points.mean(axis=0)) @ frame.T
centroid = view_points[tets].mean(axis=1)
middle = 0.5 * (view_points[:, 2].min() + view_points[:, 2].max())
kept = centroid[:, 2] < middle
cut_name = args.cut or "its thinnest section"

# The faces of the kept tets that no other kept tet shares: the cut-open solid's skin.
faces = np.concatenate([tets[kept][:, [1, 2, 3]], tets[kept][:, [0, 3, 2]], tets[kept][:, [0, 1, 3]],
                        tets[kept][:, [0, 2, 1]]])
owner = np.tile(piece[kept], 4)
key = np.sort(faces, axis=1)
_, first, count = np.unique(key, axis=0, return_index=True, return_counts=True)
skin = first[count == 1]
faces, owner = faces[skin], owner[skin]

# The other half's surface: boundary faces (in one tet) of the removed tets, drawn faint.
all_faces = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 3, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 1]]])
_, first_all, count_all = np.unique(np.sort(all_faces, axis=1), axis=0, return_index=True, return_counts=True)
boundary = first_all[count_all == 1]
removed_side = ~np.tile(kept, 4)[boundary]
ghost = all_faces[boundary[removed_side]]

def shaded(tris, rgba):
    normal = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-300
    light = np.array([0.3, -0.5, 0.8])
    light /= np.linalg.norm(light)
    out = np.array(rgba, dtype=float)
    out[:, :3] *= (0.5 + 0.5 * np.abs(normal @ light))[:, None]
    return out


palette = plt.get_cmap("tab10")
elev, azim = args.view or (32, -58)
camera = np.array([np.cos(np.radians(elev)) * np.cos(np.radians(azim)),
                   np.cos(np.radians(elev)) * np.sin(np.radians(azim)), np.sin(np.radians(elev))])
# Both sets of faces are outward (positively oriented tets); the frame keeps orientation.
mirror = np.sign(np.linalg.det(frame))
tris = view_points[np.concatenate([faces, ghost])]
rgba = np.array([(0.6, 0.6, 0.6, 1.0) if p < 0 else palette(p % 10) for p in owner] +
                [(0.78, 0.8, 0.84, 0.25)] * len(ghost))
edges = np.array([(0, 0, 0, 0.35)] * len(faces) + [(0, 0, 0, 0)] * len(ghost))
normal = mirror * np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
# One collection (matplotlib sorts faces only within one), back faces culled: no z-buffer.
front = normal @ camera > 0
rgba, edges, tris = shaded(tris[front], rgba[front]), edges[front], tris[front]

figure = plt.figure(figsize=(9, 7), dpi=130)
ax = figure.add_axes([0, 0, 1, 0.94], projection="3d")
ax.add_collection3d(Poly3DCollection(tris, facecolors=rgba, edgecolors=edges, linewidths=0.15))
low, high = view_points.min(axis=0), view_points.max(axis=0)
for set_limits, lo, hi in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), low, high):
    set_limits(lo, hi)
ax.set_box_aspect(np.maximum(high - low, 1e-9 * (high - low).max()), zoom=1.0)
ax.view_init(elev, azim)
ax.set_axis_off()
pieces = sorted(set(piece.tolist()))
ax.set_title(f"{len(tets):,} tets in {sum(p >= 0 for p in pieces)} pieces, cut open across {cut_name}"
             + (" (grey: re-meshed seams)" if -1 in pieces else ""), y=0.98)
figure.savefig(args.png, bbox_inches="tight", pad_inches=0.05)
print(f"wrote {args.png}: {len(faces):,} faces shown")
