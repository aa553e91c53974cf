// Gmsh MSH 4.1 (internal header): the single file (write_msh, mesh_formats.hpp) and the set of
// one file per partition that gmsh itself writes with Mesh.PartitionSplitMeshFiles, which
// partitioned solvers read one file per rank. A set at PREFIX is PREFIX_1.msh ... PREFIX_N.msh:
// partition i holds the tets of the i-th piece value (pieces in order, then the tets re-meshed
// at the seams). Every file has the whole model's entities (as the single file), its own
// partition's in $PartitionedEntities (a volume and the boundary surfaces, with the physical
// groups), and the nodes and elements of its partition under the single file's tags: a node on
// several partitions is in each of their files with the same tag, so `gmsh PREFIX_*.msh` shows
// the whole mesh and the set is the single file's mesh, split.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "io/mesh_formats.hpp"

namespace partet {

// The piece values in partition order (partition i + 1 holds the tets of the i-th): the pieces in
// order, then the seams' -1.
std::vector<int> msh_partition_pieces(const MeshOutput& output);

// One partition's file, as arrays any rank can write it from.
struct MshPartView {
  // partition (from 1), partitions, triangles on the boundary surface (the rest are parts of split
  // input triangles), 1 when the model has a split-boundary surface, 1 for binary.
  ArrayRun<std::uint64_t> about;
  ArrayRun<double> box;               // the whole mesh's bounds, then the partition's (min xyz, max xyz)
  ArrayRun<std::uint64_t> node_tags;  // ascending
  ArrayRun<double> xyz;               // 3 per node
  ArrayRun<std::uint64_t> triangles;  // per triangle: its element tag and 3 node tags
  ArrayRun<std::uint64_t> tets;       // per tet: its element tag and 4 node tags
};

// The arrays' bytes (what rank 0 sends the rank that writes the file), and back: nothing when
// they do not fit together (lost or cut bytes).
PieceArrays arrays_of(const MshPartView& part);
std::optional<MshPartView> msh_part_from(const PieceArrays& arrays);

// Writes one partition's file into `path`, which must exist (an OutputSet's temporary); errors
// name `shown`.
void write_msh_part(const MshPartView& part, const std::string& path, const std::string& shown);

// The partitions of a mesh, each made on demand: one pass over the tets and the boundary for all.
class MshPartitions {
 public:
  MshPartitions(const MeshOutput& output, bool binary);
  // The partition of piece value `piece`; the view is valid until the next call.
  MshPartView of(int piece);

 private:
  // Items (tets or boundary triangles) grouped by partition: order[start[p], start[p + 1]).
  struct Grouped {
    std::vector<std::uint32_t> order;
    std::vector<std::size_t> start;
  };
  void add_nodes(std::size_t partition);
  void add_elements(std::size_t partition);

  const MeshOutput output_;  // references to the mesh: cheap to copy
  bool binary_;
  std::vector<int> pieces_;
  std::vector<double> model_box_;  // the whole mesh's bounds
  Grouped tets_, triangles_;
  std::vector<std::uint32_t> taken_by_;  // per node: 1 + the last partition that took it
  // The current partition's arrays.
  std::vector<std::uint64_t> about_, node_tags_, triangle_rows_, tet_rows_;
  std::vector<double> box_, xyz_;
};

}  // namespace partet
