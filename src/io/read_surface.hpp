// Reading triangle surfaces (OFF, OBJ, PLY, STL through CGAL's IO).
#pragma once
#include <string>

#include "partet/mesh_types.hpp"

namespace partet {

// Reads a surface; the format is chosen by extension (.off .obj .ply .stl, ASCII or binary).
// Polygons with more than three corners are triangulated. Throws InputError with a one-line
// message (missing file, unknown format, unreadable or truncated content, empty mesh,
// indices out of range, NaN/inf coordinates, faces that cannot be triangulated).
SurfaceMesh read_surface(const std::string& path);

// Whether the path names a readable regular file in a supported format (before reading it);
// returns its lowercase extension. Throws InputError saying what is wrong.
std::string check_surface_path(const std::string& path);

}  // namespace partet
