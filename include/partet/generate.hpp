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

}  // namespace partet
