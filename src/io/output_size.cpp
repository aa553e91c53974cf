#include "io/output_size.hpp"

#include <algorithm>

namespace partet {
namespace {

using Bytes = std::uint64_t;

// The decimal digits of the numbers first, first + 1, ..., first + count - 1 (first >= 0).
Bytes digits_of_run(std::int64_t first, std::int64_t count) {
  Bytes total = 0;
  std::int64_t low = 0, high = 10;  // the numbers of `digits` digits: [low, high)
  for (int digits = 1; count > 0 && digits <= 19; ++digits, low = high, high = high > INT64_MAX / 10 ? INT64_MAX : high * 10) {
    const std::int64_t from = std::max(first, low), to = std::min(first + count, high);
    if (to > from) total += static_cast<Bytes>(to - from) * static_cast<Bytes>(digits);
  }
  return total;
}

// The digits of the point ids in `tets` rows of four, each of the points (numbered from `base`)
// used at least once: every id's digits once, one digit for each other use.
Bytes digits_of_tet_ids(const MeshCounts& c, std::int64_t base) {
  return digits_of_run(base, c.points) + static_cast<Bytes>(std::max<std::int64_t>(0, 4 * c.tets - c.points));
}

Bytes tetgen_bytes(const MeshCounts& c) {
  const auto p = static_cast<Bytes>(c.points), t = static_cast<Bytes>(c.tets), f = static_cast<Bytes>(c.faces);
  const Bytes node = digits_of_run(0, c.points) + 7 * p;                               // "i x y z\n"
  const Bytes ele = digits_of_run(0, c.tets) + digits_of_tet_ids(c, 0) + 5 * t;        // "i a b c d\n"
  const Bytes face = digits_of_run(0, c.faces) + 9 * f;                                // "i a b c m\n"
  const Bytes neigh = digits_of_run(0, c.tets) + 9 * t;                                // "i n n n n\n"
  return node + ele + face + neigh;
}

Bytes msh_text_bytes(const MeshCounts& c) {
  const auto p = static_cast<Bytes>(c.points), t = static_cast<Bytes>(c.tets), f = static_cast<Bytes>(c.faces);
  const Bytes nodes = digits_of_run(1, c.points) + 2 * p + 7 * p;  // "i \n" then "x y z\n"
  const Bytes triangles = digits_of_run(1, c.faces) + 8 * f;       // "i a b c \n"
  const Bytes tets = digits_of_run(1 + c.faces, c.tets) + digits_of_tet_ids(c, 1) + 6 * t;
  return nodes + triangles + tets;
}

Bytes msh_binary_bytes(const MeshCounts& c) {
  // size_t tags: a node's tag and coordinates, a triangle's tag and 3 nodes, a tet's tag and 4.
  return 32 * static_cast<Bytes>(c.points) + 32 * static_cast<Bytes>(c.faces) + 40 * static_cast<Bytes>(c.tets);
}

Bytes medit_bytes(const MeshCounts& c) {
  const auto p = static_cast<Bytes>(c.points), t = static_cast<Bytes>(c.tets), f = static_cast<Bytes>(c.faces);
  return 8 * p + 8 * f + digits_of_tet_ids(c, 1) + 6 * t;  // "x y z 0\n", "a b c 1\n", "a b c d r\n"
}

Bytes hdf5_bytes(const MeshCounts& c) {
  // Coordinates; int64 tets with int32 region and piece; int64 faces with int32 markers.
  return 24 * static_cast<Bytes>(c.points) + 40 * static_cast<Bytes>(c.tets) + 28 * static_cast<Bytes>(c.faces);
}

Bytes format_bytes(MeshFormat format, const MeshCounts& c) {
  switch (format) {
    case MeshFormat::tetgen: return tetgen_bytes(c);
    case MeshFormat::msh:
    case MeshFormat::msh_parts: return msh_text_bytes(c);
    case MeshFormat::msh_binary:
    case MeshFormat::msh_parts_binary: return msh_binary_bytes(c);
    case MeshFormat::medit: return medit_bytes(c);
    case MeshFormat::xdmf: return hdf5_bytes(c);
    case MeshFormat::vtu:
    case MeshFormat::pvtu: return 0;
  }
  return 0;
}

}  // namespace

MeshCounts least_mesh_counts(std::int64_t vertices, std::int64_t faces) {
  return {vertices, std::max((faces + 3) / 4, (vertices + 3) / 4), faces};
}

std::uint64_t least_output_bytes(const std::vector<MeshFormat>& formats, const MeshCounts& counts) {
  Bytes total = 0;
  for (MeshFormat format : formats) total += format_bytes(format, counts);
  return total;
}

}  // namespace partet
