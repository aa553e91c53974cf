// Closed, self-intersection-free test surfaces generated in code, so that the default input
// and the unit tests need no external model files.
#pragma once
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"

namespace partet {

// Known shapes: "sphere", "torus" (genus 1), "genus3" (a slab with three holes),
// "nested" (outer shell, an inward-facing cavity shell inside it, an outward island inside the
// cavity), "two_spheres" (two disjoint shells). faces is a target: the result has about that
// many triangles (at least a shape-dependent minimum). Throws OptionError for unknown shapes.
SurfaceMesh generate_surface(const std::string& shape, int faces);

std::vector<std::string> generated_shape_names();

// CAD-like parts with thin parallel walls close together, the kind that is hard to cut: a comb
// profile extruded, each flat face triangulated as CAD programs export it (vertices only at
// corners, long thin triangles). kind: "fins" (a heat sink: walls on a base plate), "comb" (long
// thin teeth), "slots" (a block with slots cut into it), "plates" (plates stacked on a spine,
// along z). Axis aligned, as CAD parts are, unless turned about the extrusion axis.
struct ThinWallPart {
  std::string kind = "fins";
  int walls = 30;
  double wall = 1;          // thickness of each wall
  double gap = 1;           // space between neighbouring walls
  double turn_degrees = 0;  // turn about the extrusion axis
};
// Throws OptionError for an unknown kind or a size that makes no part.
SurfaceMesh generate_thin_walls(const ThinWallPart& part);
std::vector<std::string> thin_wall_kinds();

}  // namespace partet
