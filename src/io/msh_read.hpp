// Reading back the Gmsh MSH 4.1 files partet writes (ASCII or binary), for `partet check`: one
// .msh file, or a set of partition files (PREFIX_1.msh ... PREFIX_N.msh, --format msh-parts).
#pragma once
#include <string>
#include <vector>

#include "io/mesh_sink.hpp"

namespace partet {

// Reads PATH into sink (node tag t is point t - 1; every triangle an outward boundary face, marker
// 1) and returns the files of its set: PATH first, then, when PATH is one file of a partition set
// (it has $PartitionedEntities), the set's other files in order. Throws InputError on a missing
// file or content that is not such a mesh (only what partet writes is read: nodes on one volume,
// 3-node triangles and 4-node tets).
std::vector<std::string> read_msh_named(const std::string& path, MeshSink& sink);

// Reads PATH, one more file of a set, into sink.
void read_msh_file(const std::string& path, MeshSink& sink);

}  // namespace partet
