// TetGen's file formats: .node .ele .face .neigh, numbered from 0. Every file of a set ends
// with the line "# partet mesh ID", the same ID (a fingerprint of the mesh) in all four, so a
// set mixed from different runs can be told apart.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "partet/mesh_types.hpp"
#include "io/output_set.hpp"

namespace partet {

enum class TetgenFile { node, ele, face, neigh };
const char* extension(TetgenFile file);  // ".node", ...

// A fingerprint of the mesh's points, tets and boundary faces: the ID written into its files.
std::string mesh_id(const TetMesh& mesh, const std::vector<Triangle>& boundary_faces);

// Writes one file of the set to `path` (errors name `shown_path`). Coordinates use 17
// significant digits so they read back bit-identical; .face holds the boundary faces with marker 1,
// or 2 from split_from on (the parts of input triangles split by points on the surface).
void write_tetgen_file(TetgenFile file, const TetMesh& mesh, const std::vector<Triangle>& boundary_faces,
                       const std::string& id, const std::string& path, const std::string& shown_path,
                       std::size_t split_from = SIZE_MAX);

// Adds PREFIX.node, .ele, .face and .neigh to an output set (published together).
void add_tetgen_files(OutputSet& set, const TetMesh& mesh, const std::vector<Triangle>& boundary_faces,
                      const std::string& prefix, std::size_t split_from = SIZE_MAX);

// Everything a set of TetGen files holds. Accepts 0- or 1-based numbering as TetGen does.
struct TetgenFileSet {
  TetMesh mesh;                  // .node and .ele; neighbours computed from the tets
  std::vector<Triangle> faces;   // .face, when present
  std::vector<Tet> neighbours;   // .neigh as written, when present
  bool has_faces = false, has_neighbours = false;
  std::vector<std::pair<std::string, std::string>> ids;  // (file, its set ID or "") of each file read
};
// Throws InputError on a missing .node/.ele or malformed content.
TetgenFileSet read_tetgen_set(const std::string& prefix);

// PREFIX.node and PREFIX.ele (and PREFIX.face, if present, into boundary_faces).
TetMesh read_tetgen_files(const std::string& prefix, std::vector<Triangle>* boundary_faces = nullptr);

}  // namespace partet
