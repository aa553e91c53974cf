// Writing the final tet mesh in the formats users open: VTK XML (.vtu, and .pvtu with one .vtu
// per piece), Gmsh MSH 4.1 (ASCII or binary) and MEDIT (.mesh). TetGen's own files are in
// tetgen_files.hpp. Every writer writes exactly one file, to the path it is given (the caller
// publishes a set of files atomically under their final names). Throws OutputError.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "partet/mesh_types.hpp"

namespace partet {

// What the writers write.
struct MeshOutput {
  const TetMesh& mesh;                    // positively oriented tets; mesh.piece per tet if known
  const std::vector<Triangle>& boundary;  // the input triangles, outward, in mesh numbering
};

// VTK XML UnstructuredGrid, binary appended data, zlib-compressed. Cell data: "piece" (the piece
// that meshed the tet, -1: re-meshed around a cut) and "region" (the connected solid it belongs
// to, from 1). With only_piece >= 0, just that piece's tets (and the points they use).
void write_vtu(const MeshOutput& output, const std::string& path, int only_piece = -1);

// The .pvtu index naming one .vtu per piece (as written by write_vtu(output, ..., piece)); the
// names are stored as given (relative to the .pvtu's directory).
void write_pvtu(const MeshOutput& output, const std::string& path, const std::vector<std::string>& piece_files);

// The piece indices a .pvtu set has files for, in order (the -1 group included when present).
std::vector<int> pieces_in(const MeshOutput& output);

// Gmsh MSH 4.1: nodes, tetrahedra (physical group 1 "volume") and the boundary triangles
// (physical group 2 "boundary"), with entities for the volume and the boundary surface.
void write_msh(const MeshOutput& output, const std::string& path, bool binary);

// MEDIT .mesh (ASCII, version 2): Vertices, Tetrahedra (reference = region) and Triangles
// (reference 1: the boundary).
void write_medit(const MeshOutput& output, const std::string& path);

}  // namespace partet
