// Loop subdivision of a closed surface: a way for anyone to turn a shared model into a
// multi-million-face input (each step multiplies the face count by 4).
#pragma once
#include <cstddef>

#include "partet/mesh_types.hpp"

namespace partet {

// `steps` steps of CGAL's Loop subdivision. The surface stays closed, manifold and of the same
// genus; for smooth models it also stays free of self-intersections (not checked here).
// Throws InputError when the surface is not a closed manifold, OptionError for steps < 0.
SurfaceMesh loop_subdivide(const SurfaceMesh& surface, int steps);

// Refuses (OptionError, saying why) a subdivision whose result would have more than 2^31 faces or
// need more memory than the machine has available.
void check_subdivision_fits(std::size_t faces, int steps);

}  // namespace partet
