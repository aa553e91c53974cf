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
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/point_ids.hpp"
#include "io/mesh_formats.hpp"
#include "stages/info.hpp"
#include "stages/topology.hpp"

namespace partet {

// The piece values in partition order (partition i + 1 holds the tets of the i-th): the pieces in
// order, then the seams' -1.
std::vector<int> msh_partition_pieces(const MeshOutput& output);
// The same order from the piece values as pieces_in lists them (the seams' -1 first).
std::vector<int> msh_partition_order(std::vector<int> pieces);

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

// One partition's arrays, owned: made from the assembled mesh (MshPartitions) or, for a mesh
// left spread, by the rank keeping the partition's bulk.
struct MshPartArrays {
  std::vector<std::uint64_t> about, node_tags, triangles, tets;
  std::vector<double> box, xyz;
  MshPartView view() const {
    return {run_of(about), run_of(box), run_of(node_tags), run_of(xyz), run_of(triangles), run_of(tets)};
  }
};

// What a partition's file says of the whole: its place among the partitions, the element tags'
// base, the boundary's split surface and the encoding.
struct MshPartHead {
  std::uint64_t partition = 0, partitions = 0;  // partition from 1
  std::uint64_t boundary = 0;                   // boundary triangles (a tet's element tag: boundary + row + 1)
  std::size_t split_from = 0;                   // the boundary's parts of split input triangles from here
  bool binary = false;
  Bounds model;  // the whole mesh's bounds
};

// A partition's tets in row order, wherever they are: tet(i) in whole-mesh point ids, at row(i).
struct MshPartTets {
  std::size_t count = 0;
  std::function<GlobalTet(std::size_t)> tet;  // in the whole mesh's ids
  std::function<std::int64_t(std::size_t)> row;
};

// A partition's arrays from its tets, its boundary triangles' rows (MshBoundaryParts::rows) and
// the coordinates of its points (point(id), 3 doubles; ids from 0).
MshPartArrays msh_part_arrays(const MshPartHead& head, const MshPartTets& tets, std::vector<std::uint64_t> triangles,
                              const std::function<Point3(std::int64_t)>& point);

// The partition of every boundary triangle, found from the tets it is a face of: each block of
// tets (the assembled mesh; a spread mesh's band, its bulks) adds its open faces, and those that
// are boundary triangles take the partition of their tet. Then each partition's triangle rows.
class MshBoundaryParts {
 public:
  explicit MshBoundaryParts(const std::vector<Triangle>& boundary);
  // The open faces of the tets (every face when neighbours is empty), tet t's in partition_of(t)
  // (from 0). On every usable CPU.
  void add_tets(const std::vector<Tet>& tets, const std::vector<Tet>& neighbours,
                const std::function<std::uint32_t(std::size_t)>& partition_of);
  // Faces given by their vertex sets (ascending): a bulk's open faces, as its owner sends them.
  void add_faces(const std::vector<std::array<std::int32_t, 3>>& faces, std::uint32_t partition);
  // Groups the triangles by partition, and frees the lookup. Throws InternalError when a boundary
  // triangle is no tet's face.
  void group(std::size_t partitions);
  // Partition p's triangles (ascending) as rows: the element tag (from 1), then the node tags.
  std::vector<std::uint64_t> rows(std::size_t partition) const;

 private:
  static constexpr std::uint32_t kNone = UINT32_MAX;
  const std::vector<Triangle>& boundary_;
  // The lookup: entries bucketed by their smallest vertex, bucket v at [start_[v], start_[v + 1]).
  std::vector<std::uint32_t> start_;
  std::vector<FaceSlot> entries_;         // slot: the triangle
  std::vector<std::uint32_t> partition_;  // per triangle (kNone until found)
  std::vector<std::uint32_t> order_;      // grouped
  std::vector<std::size_t> first_;
  void found(const FaceKey& face, std::uint32_t partition);
};

// The partitions of an assembled mesh, each made on demand: one pass over the tets and the
// boundary for all.
class MshPartitions {
 public:
  MshPartitions(const MeshOutput& output, bool binary);
  // The partition of piece value `piece`; the view is valid until the next call.
  MshPartView of(int piece);

 private:
  const MeshOutput output_;  // references to the mesh: cheap to copy
  MshPartHead head_;
  std::vector<int> pieces_;
  std::vector<std::uint32_t> tet_order_;  // tets grouped by partition: [tet_start_[p], tet_start_[p + 1])
  std::vector<std::size_t> tet_start_;
  MshBoundaryParts triangles_;
  MshPartArrays current_;
};

}  // namespace partet
