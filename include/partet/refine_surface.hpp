// Loop subdivision of a closed surface: a way for anyone to turn a shared model into a
// multi-million-face input (each step multiplies the face count by 4).
#pragma once
#include "partet/mesh_types.hpp"

namespace partet {

// `steps` steps of CGAL's Loop subdivision. The surface stays closed, manifold and of the same
// genus; for smooth models it also stays free of self-intersections (not checked here).
// Throws InputError when the surface is not a closed manifold, OptionError for steps < 0.
SurfaceMesh loop_subdivide(const SurfaceMesh& surface, int steps);

}  // namespace partet
