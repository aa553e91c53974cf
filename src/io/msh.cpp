// Gmsh MSH 4.1, one file or one per partition. Checked in the tests by gmsh itself (and meshio
// for the single file).
#include "io/msh.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "common/group_items.hpp"
#include "common/id_bits.hpp"
#include "common/parallel.hpp"
#include "io/buffered_file.hpp"
#include "io/msh_numbers.hpp"
#include "io/row_lines.hpp"
#include "partet/errors.hpp"
#include "stages/info.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// The model, in every file: one volume (tag 1, physical 1 "volume") bounded by the boundary
// surface (tag 1, physical 2 "boundary") and, when TetGen split input triangles, the split
// boundary surface (tag 2, physical 3 "split boundary").
constexpr std::int32_t kVolumePhysical = 1;
std::int32_t surface_physical(std::int32_t surface) { return surface + 1; }

// An MSH file: its numbers (MshNumbers) and the sections every file has.
class MshStream {
 public:
  MshStream(const std::string& path, const std::string& shown, bool must_exist, bool binary)
      : out_(path, shown, must_exist), numbers_(out_, binary) {}

  void size(std::uint64_t v) { numbers_.size(v); }
  void tag(std::int32_t v) { numbers_.tag(v); }
  void real(double v) { numbers_.real(v); }
  void end_line() { numbers_.end_line(); }
  void box(const Bounds& b) {
    for (double v : b.min) real(v);
    for (double v : b.max) real(v);
  }
  void begin_section(const char* name) { out_.text(name); }
  void end_section(const char* name) {
    if (binary()) out_.newline();
    out_.text(name);
  }
  void close() { out_.close(); }
  BufferedFile& file() { return out_; }
  bool binary() const { return numbers_.binary(); }

  // $MeshFormat, $PhysicalNames and $Entities (the model).
  void model(const Bounds& box, bool split) {
    out_.text(binary() ? "$MeshFormat\n4.1 1 8\n" : "$MeshFormat\n4.1 0 8\n");
    if (binary()) {
      const int one = 1;  // lets readers detect the byte order
      out_.bytes(&one, sizeof one);
      out_.newline();
    }
    out_.text(split ? "$EndMeshFormat\n$PhysicalNames\n3\n2 2 \"boundary\"\n2 3 \"split boundary\"\n"
                      "3 1 \"volume\"\n$EndPhysicalNames\n"
                    : "$EndMeshFormat\n$PhysicalNames\n2\n2 2 \"boundary\"\n3 1 \"volume\"\n$EndPhysicalNames\n");
    begin_section("$Entities\n");
    const std::int32_t surfaces = split ? 2 : 1;
    size(0), size(0), size(surfaces), size(1), end_line();
    for (std::int32_t s = 1; s <= surfaces; ++s) {
      tag(s), this->box(box);
      size(1), tag(surface_physical(s)), size(0), end_line();
    }
    tag(1), this->box(box);
    size(1), tag(kVolumePhysical), size(surfaces);
    for (std::int32_t s = 1; s <= surfaces; ++s) tag(s);
    end_line();
    end_section("$EndEntities\n");
  }

 private:
  BufferedFile out_;
  MshNumbers<BufferedFile> numbers_;
};

// ---------------------------------------------------------------------------------------------
// The single file: every node on the volume, the boundary triangles, then the tets.

class MshWriter {
 public:
  MshWriter(const MeshRows& rows, const std::vector<Triangle>& boundary, std::size_t split_from,
            const std::string& path, const std::string& shown, bool binary)
      : rows_(rows),
        boundary_(boundary),
        whole_(std::min(split_from, boundary.size())),
        out_(path, shown, false, binary) {}

  void write() {
    out_.model(rows_.box, split());
    nodes();
    elements();
    out_.close();
  }

 private:
  void nodes() {
    const std::uint64_t n = rows_.points;
    out_.begin_section("$Nodes\n");
    out_.size(1), out_.size(n), out_.size(n == 0 ? 0 : 1), out_.size(n), out_.end_line();
    out_.tag(3), out_.tag(1), out_.tag(0), out_.size(n), out_.end_line();
    for (std::uint64_t i = 1; i <= n; ++i) out_.size(i), out_.end_line();
    rows_.write(out_.file(), out_.binary() ? RowLines::msh_node_binary : RowLines::msh_node, 0);
    out_.end_section("$EndNodes\n");
  }

  void elements() {
    const std::uint64_t tets = rows_.tets, triangles = boundary_.size();
    out_.begin_section("$Elements\n");
    // Empty blocks are left out (meshio cannot read them).
    const std::uint64_t blocks = 1 + (whole_ > 0 ? 1 : 0) + (split() ? 1 : 0);
    out_.size(blocks), out_.size(tets + triangles), out_.size(1), out_.size(tets + triangles), out_.end_line();
    std::uint64_t id = 1;
    auto surface = [&](std::int32_t entity, std::size_t begin, std::size_t end) {
      out_.tag(2), out_.tag(entity), out_.tag(2), out_.size(end - begin), out_.end_line();  // 2: 3-node triangle
      for (std::size_t i = begin; i < end; ++i) {
        out_.size(id++);
        for (std::int32_t v : boundary_[i]) out_.size(static_cast<std::uint64_t>(v) + 1);
        out_.end_line();
      }
    };
    if (whole_ > 0) surface(1, 0, whole_);
    if (split()) surface(2, whole_, boundary_.size());
    out_.tag(3), out_.tag(1), out_.tag(4), out_.size(tets), out_.end_line();  // 4: 4-node tetrahedron
    rows_.write(out_.file(), out_.binary() ? RowLines::msh_tet_binary : RowLines::msh_tet,
                static_cast<std::int64_t>(id));
    out_.end_section("$EndElements\n");
  }

  bool split() const { return whole_ < boundary_.size(); }

  const MeshRows& rows_;
  const std::vector<Triangle>& boundary_;
  std::size_t whole_;  // boundary faces before the parts of split input triangles
  MshStream out_;
};

// ---------------------------------------------------------------------------------------------
// One partition's file. Partition p's entities: its volume (tag p + 1, parent volume 1) and its
// part of each boundary surface s (tag p * surfaces + s, parent surface s), so that no partition
// entity shares a tag with a model entity or another partition's.

struct Partition {
  std::uint64_t index = 0, count = 0, whole = 0;  // whole: triangles on the boundary surface
  bool split = false, binary = false;
  std::int32_t surfaces() const { return split ? 2 : 1; }
  std::int32_t volume_tag() const { return static_cast<std::int32_t>(index) + 1; }
  std::int32_t surface_tag(std::int32_t s) const { return static_cast<std::int32_t>(index) * surfaces() + s; }
};

Bounds box_at(const double* v) { return {{v[0], v[1], v[2]}, {v[3], v[4], v[5]}}; }

class MshPartWriter {
 public:
  MshPartWriter(const MshPartView& part, const std::string& path, const std::string& shown)
      : part_(part),
        p_{part.about.data[0], part.about.data[1], part.about.data[2], part.about.data[3] != 0,
           part.about.data[4] != 0},
        out_(path, shown, /*must_exist=*/true, p_.binary) {}

  void write() {
    out_.model(box_at(part_.box.data), p_.split);
    partitioned_entities();
    nodes();
    elements();
    out_.close();
  }

 private:
  void partitioned_entities() {
    const Bounds box = box_at(part_.box.data + 6);
    out_.begin_section("$PartitionedEntities\n");
    out_.size(p_.count), out_.end_line();
    out_.size(0), out_.end_line();  // no ghost entities
    out_.size(0), out_.size(0), out_.size(static_cast<std::uint64_t>(p_.surfaces())), out_.size(1), out_.end_line();
    for (std::int32_t s = 1; s <= p_.surfaces(); ++s) {
      out_.tag(p_.surface_tag(s)), out_.tag(2), out_.tag(s), out_.size(1),
          out_.tag(static_cast<std::int32_t>(p_.index));
      out_.box(box), out_.size(1), out_.tag(surface_physical(s)), out_.size(0), out_.end_line();
    }
    out_.tag(p_.volume_tag()), out_.tag(3), out_.tag(1), out_.size(1), out_.tag(static_cast<std::int32_t>(p_.index));
    out_.box(box), out_.size(1), out_.tag(kVolumePhysical), out_.size(static_cast<std::uint64_t>(p_.surfaces()));
    for (std::int32_t s = 1; s <= p_.surfaces(); ++s) out_.tag(p_.surface_tag(s));
    out_.end_line();
    out_.end_section("$EndPartitionedEntities\n");
  }

  void nodes() {
    const std::size_t n = part_.node_tags.size;
    const std::uint64_t* tags = part_.node_tags.data;
    out_.begin_section("$Nodes\n");
    out_.size(n == 0 ? 0 : 1), out_.size(n), out_.size(n == 0 ? 0 : tags[0]), out_.size(n == 0 ? 0 : tags[n - 1]);
    out_.end_line();
    if (n > 0) {
      out_.tag(3), out_.tag(p_.volume_tag()), out_.tag(0), out_.size(n), out_.end_line();
      for (std::size_t i = 0; i < n; ++i) out_.size(tags[i]), out_.end_line();
      write_row_lines(out_.file(), p_.binary ? RowLines::msh_node_binary : RowLines::msh_node, {part_.xyz.data, n});
    }
    out_.end_section("$EndNodes\n");
  }

  void elements() {
    const std::size_t triangles = part_.triangles.size / 4, tets = part_.tets.size / 5;
    const std::size_t blocks = (p_.whole > 0) + (triangles > p_.whole) + (tets > 0);
    std::uint64_t lowest = UINT64_MAX, highest = 0;
    for (std::size_t i = 0; i < part_.triangles.size; i += 4)
      lowest = std::min(lowest, part_.triangles.data[i]), highest = std::max(highest, part_.triangles.data[i]);
    for (std::size_t i = 0; i < part_.tets.size; i += 5)
      lowest = std::min(lowest, part_.tets.data[i]), highest = std::max(highest, part_.tets.data[i]);
    out_.begin_section("$Elements\n");
    out_.size(blocks), out_.size(triangles + tets), out_.size(blocks == 0 ? 0 : lowest), out_.size(highest);
    out_.end_line();
    // Empty blocks are left out, as in the single file.
    block(2, p_.surface_tag(1), 2, part_.triangles.data, p_.whole, 4);
    block(2, p_.surface_tag(2), 2, part_.triangles.data + 4 * p_.whole, triangles - p_.whole, 4);
    block(3, p_.volume_tag(), 4, part_.tets.data, tets, 5);
    out_.end_section("$EndElements\n");
  }

  // A block of `count` rows of `width` numbers (the element tag, then its node tags).
  void block(std::int32_t dim, std::int32_t entity, std::int32_t type, const std::uint64_t* rows, std::size_t count,
             std::size_t width) {
    if (count == 0) return;
    out_.tag(dim), out_.tag(entity), out_.tag(type), out_.size(count), out_.end_line();
    for (std::size_t i = 0; i < count * width; i += width) {
      for (std::size_t j = 0; j < width; ++j) out_.size(rows[i + j]);
      out_.end_line();
    }
  }

  const MshPartView& part_;
  Partition p_;
  MshStream out_;
};

}  // namespace

std::vector<int> msh_partition_pieces(const MeshOutput& output) { return msh_partition_order(pieces_in(output)); }

std::vector<int> msh_partition_order(std::vector<int> pieces) {
  if (!pieces.empty() && pieces.front() < 0) std::rotate(pieces.begin(), pieces.begin() + 1, pieces.end());
  return pieces;
}

void write_msh(const MeshRows& rows, const std::vector<Triangle>& boundary, std::size_t split_from,
               const std::string& path, const std::string& shown, bool binary) {
  MshWriter(rows, boundary, split_from, path, shown, binary).write();
}

PieceArrays arrays_of(const MshPartView& part) {
  return {bytes_of(part.about), bytes_of(part.box),       bytes_of(part.node_tags),
          bytes_of(part.xyz),   bytes_of(part.triangles), bytes_of(part.tets)};
}

std::optional<MshPartView> msh_part_from(const PieceArrays& arrays) {
  MshPartView part;
  const bool whole = as_runs(arrays, part.about, part.box, part.node_tags, part.xyz, part.triangles, part.tets) &&
                     part.about.size == 5 && part.box.size == 12 && part.xyz.size == 3 * part.node_tags.size &&
                     part.triangles.size % 4 == 0 && part.tets.size % 5 == 0 &&
                     part.about.data[2] <= part.triangles.size / 4 && part.about.data[0] >= 1 &&
                     part.about.data[0] <= part.about.data[1] && part.about.data[1] < (1u << 30);
  if (!whole) return std::nullopt;
  return part;
}

void write_msh_part(const MshPartView& part, const std::string& path, const std::string& shown) {
  MshPartWriter(part, path, shown).write();
}

MshPartArrays msh_part_arrays(const MshPartHead& head, const MshPartTets& tets, std::vector<std::uint64_t> triangles,
                              const std::function<Point3(std::int64_t)>& point) {
  MshPartArrays part;
  // The nodes: every point the tets use, ascending.
  part.node_tags = distinct_ascending<std::uint64_t>([&](const auto& use) {
    for (std::size_t i = 0; i < tets.count; ++i)
      for (std::int64_t v : tets.tet(i)) use(static_cast<std::uint64_t>(v));
  });
  part.xyz.reserve(3 * part.node_tags.size());
  for (std::uint64_t& tag : part.node_tags) {
    const Point3 p = point(static_cast<std::int64_t>(tag));
    part.xyz.insert(part.xyz.end(), p.begin(), p.end());
    ++tag;  // MSH's tags from 1
  }
  Bounds own{{0, 0, 0}, {0, 0, 0}};
  for (std::size_t i = 0; i < part.xyz.size(); i += 3)
    for (int c = 0; c < 3; ++c) {
      own.min[c] = i == 0 ? part.xyz[c] : std::min(own.min[c], part.xyz[i + c]);
      own.max[c] = i == 0 ? part.xyz[c] : std::max(own.max[c], part.xyz[i + c]);
    }
  for (const Bounds& b : {head.model, own}) {
    part.box.insert(part.box.end(), b.min.begin(), b.min.end());
    part.box.insert(part.box.end(), b.max.begin(), b.max.end());
  }
  // The elements, tagged as in the single file: the boundary triangles from 1, then the tets.
  part.triangles = std::move(triangles);
  std::uint64_t whole = 0;
  for (std::size_t i = 0; i < part.triangles.size(); i += 4) whole += part.triangles[i] <= head.split_from;
  part.tets.reserve(5 * tets.count);
  for (std::size_t i = 0; i < tets.count; ++i) {
    part.tets.push_back(head.boundary + static_cast<std::uint64_t>(tets.row(i)) + 1);
    for (std::int64_t v : tets.tet(i)) part.tets.push_back(static_cast<std::uint64_t>(v) + 1);
  }
  part.about = {head.partition, head.partitions, whole, head.split_from < head.boundary ? 1u : 0u,
                head.binary ? 1u : 0u};
  return part;
}

MshBoundaryParts::MshBoundaryParts(const std::vector<Triangle>& boundary)
    : boundary_(boundary), partition_(boundary.size(), kNone) {
  // start_[v]: the first entry of vertex v's bucket, by a counting sort that leaves it there.
  std::int32_t highest = -1;
  for (const Triangle& t : boundary) highest = std::max({highest, t[0], t[1], t[2]});
  start_.assign(static_cast<std::size_t>(highest) + 2, 0);
  for (const Triangle& t : boundary) ++start_[FaceKey(t).v[0] + 1];
  for (std::size_t v = 1; v < start_.size(); ++v) start_[v] += start_[v - 1];
  entries_.resize(boundary.size());
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    const FaceKey key(boundary[i]);
    entries_[start_[key.v[0]]++] = {key.v[1], key.v[2], static_cast<std::uint32_t>(i)};
  }
  for (std::size_t v = start_.size() - 1; v > 0; --v) start_[v] = start_[v - 1];
  start_[0] = 0;
}

void MshBoundaryParts::found(const FaceKey& face, std::uint32_t partition) {
  if (face.v[0] < 0 || static_cast<std::size_t>(face.v[0]) + 1 >= start_.size()) return;
  for (std::size_t i = start_[face.v[0]]; i < start_[face.v[0] + 1]; ++i)
    if (entries_[i].mid == face.v[1] && entries_[i].high == face.v[2]) partition_[entries_[i].slot] = partition;
}

void MshBoundaryParts::add_tets(const std::vector<Tet>& tets, const std::vector<Tet>& neighbours,
                                const std::function<std::uint32_t(std::size_t)>& partition_of) {
  const bool open_faces_known = neighbours.size() == tets.size();
  // Bound by memory latency: on every usable CPU (each triangle is one tet's face, so no two
  // threads write the same entry).
  constexpr std::size_t kTetsPerTask = std::size_t{1} << 16;
  const std::size_t tasks = (tets.size() + kTetsPerTask - 1) / kTetsPerTask;
  parallel_for(tasks, usable_cpus(), [&](std::size_t task) {
    const std::size_t end = std::min(tets.size(), (task + 1) * kTetsPerTask);
    for (std::size_t t = task * kTetsPerTask; t < end; ++t)
      for (int j = 0; j < 4; ++j)
        if (!open_faces_known || neighbours[t][j] < 0) found(FaceKey(outward_face(tets[t], j)), partition_of(t));
  });
}

void MshBoundaryParts::add_faces(const std::vector<std::array<std::int32_t, 3>>& faces, std::uint32_t partition) {
  for (const auto& face : faces) found(FaceKey(face), partition);
}

void MshBoundaryParts::group(std::size_t partitions) {
  const auto lost = std::find(partition_.begin(), partition_.end(), kNone);
  if (lost != partition_.end())
    throw InternalError("boundary triangle " + std::to_string(lost - partition_.begin()) +
                        " is not a face of any tet: the mesh cannot be split into MSH partitions");
  std::vector<std::uint32_t>().swap(start_);
  std::vector<FaceSlot>().swap(entries_);
  group_items(
      boundary_.size(), partitions, [&](std::size_t i) { return partition_[i]; }, order_, first_);
}

std::vector<std::uint64_t> MshBoundaryParts::rows(std::size_t partition) const {
  std::vector<std::uint64_t> rows;
  rows.reserve(4 * (first_.at(partition + 1) - first_[partition]));
  // Ascending: the grouping is stable.
  for (std::size_t k = first_[partition]; k < first_[partition + 1]; ++k) {
    const std::uint32_t i = order_[k];
    rows.push_back(std::uint64_t{i} + 1);
    for (std::int32_t v : boundary_[i]) rows.push_back(static_cast<std::uint64_t>(v) + 1);
  }
  return rows;
}

MshPartitions::MshPartitions(const MeshOutput& output, bool binary)
    : output_(output), pieces_(msh_partition_pieces(output)), triangles_(output.boundary) {
  const TetMesh& mesh = output.mesh;
  head_.partitions = pieces_.size();
  head_.boundary = output.boundary.size();
  head_.split_from = std::min(output.split_from, output.boundary.size());
  head_.binary = binary;
  head_.model = bounds_of(mesh.points);
  const int highest = pieces_.empty() ? 0 : *std::max_element(pieces_.begin(), pieces_.end());
  std::vector<std::uint32_t> partition_of_piece(static_cast<std::size_t>(highest) + 2, 0);  // slot piece + 1
  for (std::size_t p = 0; p < pieces_.size(); ++p) partition_of_piece[pieces_[p] + 1] = static_cast<std::uint32_t>(p);
  const auto partition_of_tet = [&](std::size_t t) -> std::uint32_t {
    return partition_of_piece[(mesh.piece.empty() ? -1 : mesh.piece[t]) + 1];
  };
  group_items(mesh.tets.size(), pieces_.size(), partition_of_tet, tet_order_, tet_start_);
  triangles_.add_tets(mesh.tets, mesh.neighbours, partition_of_tet);
  triangles_.group(pieces_.size());
}

MshPartView MshPartitions::of(int piece) {
  const auto found = std::find(pieces_.begin(), pieces_.end(), piece);
  if (found == pieces_.end()) throw InternalError("no MSH partition holds piece " + std::to_string(piece));
  const auto partition = static_cast<std::size_t>(found - pieces_.begin());
  MshPartHead head = head_;
  head.partition = partition + 1;
  const std::uint32_t* order = tet_order_.data() + tet_start_[partition];
  const TetMesh& mesh = output_.mesh;
  const MshPartTets tets{tet_start_[partition + 1] - tet_start_[partition],
                         [&](std::size_t i) { return PointIds{}(mesh.tets[order[i]]); },
                         [&](std::size_t i) { return static_cast<std::int64_t>(order[i]); }};
  current_ = msh_part_arrays(head, tets, triangles_.rows(partition), [&](std::int64_t id) { return mesh.points[id]; });
  return current_.view();
}

}  // namespace partet
