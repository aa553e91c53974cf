// Reading back the MEDIT .mesh files partet writes (ASCII, version 2), for `partet check`:
// Vertices, Triangles (the outward boundary; reference 2: parts of split input triangles) and
// Tetrahedra. Any other section is refused: only what partet writes is read.
#pragma once
#include <string>

#include "io/mesh_sink.hpp"

namespace partet {

// Reads PATH into sink (vertex i, from 1, is point i - 1). Throws InputError on a missing file or
// content that is not such a mesh.
void read_medit_file(const std::string& path, MeshSink& sink);

}  // namespace partet
