// Reading back the Gmsh MSH 4.1 files partet writes (ASCII or binary), for `partet check`: one
// .msh file, or a set of partition files (PREFIX_1.msh ... PREFIX_N.msh, --format msh-parts).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

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

// What some files of an MSH set give, as they give it (for a check on several ranks, each reading
// some of the files): point ids are node tags - 1, in 64 bits; a node in several files is listed
// once per file, its coordinates unchecked.
struct MshPart {
  std::vector<std::int64_t> node_ids;
  std::vector<Point3> nodes;  // nodes[i] is point node_ids[i]
  std::vector<std::array<std::int64_t, 4>> tets;
  std::vector<std::array<std::int64_t, 3>> triangles;  // outward boundary faces
};

// Reads PATH into part; returns the files of its set, PATH first, then the other partition files
// in order (just PATH when it is a single file). Throws InputError as read_msh_set does.
std::vector<std::string> read_msh_named(const std::string& path, MshPart& part);

// Adds the nodes and cells of PATH, one more file of a set, to part.
void read_msh_file(const std::string& path, MshPart& part);

}  // namespace partet
