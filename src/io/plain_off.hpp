// A fast reader for plain ASCII OFF, the common case and most of the reading time on large
// inputs (internal header).
#pragma once
#include <optional>
#include <string>

#include "partet/mesh_types.hpp"

namespace partet {

// Parses "OFF", the counts, one vertex of three finite coordinates per line and one triangle
// "3 i j k" per line (indices in range), with '#' comments and CRLF allowed. Anything else
// (other keywords, polygons, colours, numbers spread over lines, non-finite or out-of-range
// values, trailing content) gives nullopt, and the general reader (CGAL, with its diagnostics)
// reads the file instead. Coordinates are the same doubles CGAL reads (correctly rounded).
std::optional<SurfaceMesh> read_plain_off(const std::string& path);

// The general reader (CGAL's, every format, with one-line diagnostics), which read_surface
// falls back to.
SurfaceMesh read_surface_general(const std::string& path);

}  // namespace partet
