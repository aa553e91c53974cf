// Reading back the Gmsh MSH 4.1 files partet writes (ASCII or binary), for `partet check`: one
// .msh file, or a set of partition files (PREFIX_1.msh ... PREFIX_N.msh, --format msh-parts).
#pragma once
#include <string>

#include "io/tetgen_files.hpp"

namespace partet {

// The nodes, tets and triangles of PATH, in the shape check_mesh_files reads: points by node tag
// (tag 1 is point 0), the tets, and every triangle as a boundary face (outward, as partet writes
// them); neighbours computed from the tets. When PATH is one file of a partition set (it has
// $PartitionedEntities), the whole set is read: a node in several files must have the same
// coordinates in each, and every tag from 1 to the highest must be some file's. Throws InputError
// on a missing file or content that is not such a mesh (only what partet writes is read: nodes
// on one volume, 3-node triangles and 4-node tets).
TetgenFileSet read_msh_set(const std::string& path);

}  // namespace partet
