// TetGen's file formats: .node .ele .face .neigh (1-based indices are not used: indices start
// at 0, as the first line of each file says through TetGen's conventions).
#pragma once
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"

namespace partet {

// Writes PREFIX.node, PREFIX.ele, PREFIX.face (the given boundary faces, marker 1) and
// PREFIX.neigh. Coordinates use 17 significant digits so they read back bit-identical.
// Each file is written to a temporary name and renamed at the end. Throws OutputError.
void write_tetgen_files(const TetMesh& mesh, const std::vector<Triangle>& boundary_faces, const std::string& prefix);

// Reads PREFIX.node and PREFIX.ele (and PREFIX.face if present into boundary_faces).
// Accepts 0- or 1-based numbering as TetGen does. Throws InputError.
TetMesh read_tetgen_files(const std::string& prefix, std::vector<Triangle>* boundary_faces = nullptr);

}  // namespace partet
