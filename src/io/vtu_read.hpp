// Reading back the VTK XML files partet writes, for `partet check`: one .vtu (every tet, points
// numbered as in the TetGen files, from 0) or a .pvtu set (an index naming one .vtu per piece,
// whose points kGlobalPointIds numbers as in the whole mesh). Only what partet writes is read:
// an UnstructuredGrid of tets, its arrays appended raw and zlib-compressed with UInt64 headers.
// A .vtu has no boundary triangles: the check takes the faces in one tet for them.
#pragma once
#include <string>
#include <vector>

#include "io/mesh_sink.hpp"

namespace partet {

// The files of the .pvtu set PATH names: PATH, then its piece files in the order it names them
// (relative names resolved against PATH's directory). Throws InputError when PATH cannot be read
// or is not such an index.
std::vector<std::string> pvtu_files(const std::string& path);

// Reads the points and tets of PATH into sink. A piece file of a set (in_set) must carry
// kGlobalPointIds, and its points are given by them; a single .vtu's are numbered from 0. Throws
// InputError on a missing file or content that is not such a mesh.
void read_vtu_file(const std::string& path, MeshSink& sink, bool in_set);

}  // namespace partet
