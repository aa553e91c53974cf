// Reading back the formats partet writes with cells, for `partet check`: an MSH file or partition
// set (msh_read.hpp), a .vtu or a .pvtu set (vtu_read.hpp), a MEDIT .mesh (medit_read.hpp), each
// named by one path. TetGen files have their own reader (tetgen_files.hpp), the XDMF set its own
// (xdmf.hpp).
#pragma once
#include <string>
#include <vector>

#include "io/mesh_sink.hpp"
#include "io/tetgen_files.hpp"

namespace partet {

// Whether PATH names a mesh these readers read: PREFIX.msh (one file of a partition set names
// the set), PREFIX.vtu, PREFIX.pvtu (the set) or PREFIX.mesh.
bool reads_mesh_file(const std::string& path);

// The files that list the boundary triangles of the set PATH names, as messages call them ("the
// MSH files", "the MEDIT file"); "" when its format lists none: VTK files hold only the tets, and
// the boundary is then the faces in one tet, checked against the input.
std::string boundary_list(const std::string& path);
inline bool lists_boundary(const std::string& path) { return !boundary_list(path).empty(); }

// Reads what PATH itself holds into sink (a .pvtu index holds no cells) and returns the files of
// its set: PATH first, then the others in order (an MSH partition set's other files, a .pvtu
// index's piece files). Throws InputError on a missing file or content partet does not write.
std::vector<std::string> read_named_mesh_file(const std::string& path, MeshSink& sink);

// Reads `file`, one of the others read_named_mesh_file(path) listed, into sink.
void read_set_file(const std::string& path, const std::string& file, MeshSink& sink);

// The whole set PATH names, in the shape check_mesh_files reads: points by id, the tets, the
// boundary triangles (outward, as partet writes them) when the format lists them, neighbours
// computed from the tets. A point in several files must have the same coordinates in each, and
// every id from 0 to the highest must be some file's. Throws InputError.
TetgenFileSet read_mesh_set(const std::string& path);

}  // namespace partet
