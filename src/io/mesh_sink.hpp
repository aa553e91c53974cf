// What a mesh file gives, handed on as it is read. The readers of the formats partet writes with
// cells (MSH, VTU, MEDIT: mesh_read.hpp) call a sink, which either assembles the whole mesh (partet
// check in one process) or keeps the rows as given (a rank's part of a check on several ranks).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "partet/mesh_types.hpp"

namespace partet {

// Point ids from 0 in the whole mesh, in 64 bits (a set may be checked on several ranks because
// it is too large for 32-bit ids).
using MeshId = std::int64_t;

class MeshSink {
 public:
  virtual ~MeshSink() = default;
  virtual void node(MeshId id, const Point3& point) = 0;
  virtual void tet(const std::array<MeshId, 4>& ids) = 0;
  // An outward boundary face; marker 2: a part of an input triangle split by points on the surface.
  virtual void triangle(const std::array<MeshId, 3>& ids, int marker) = 0;
};

// The rows as the files give them: a node in several files is listed once per file, its
// coordinates unchecked.
struct MeshPart : MeshSink {
  std::vector<MeshId> node_ids;
  std::vector<Point3> nodes;  // nodes[i] is point node_ids[i]
  std::vector<std::array<MeshId, 4>> tets;
  std::vector<std::array<MeshId, 3>> triangles;
  std::vector<std::int32_t> markers;  // per triangle

  void node(MeshId id, const Point3& point) override {
    node_ids.push_back(id);
    nodes.push_back(point);
  }
  void tet(const std::array<MeshId, 4>& ids) override { tets.push_back(ids); }
  void triangle(const std::array<MeshId, 3>& ids, int marker) override {
    triangles.push_back(ids);
    markers.push_back(marker);
  }
};

}  // namespace partet
