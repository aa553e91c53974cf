// The least room a mesh's files can take, from its counts alone (internal header). partet checks
// it against the output filesystem's free space twice: before the meshing, from the input's
// counts, so that a full disk costs a second, not the hours of meshing before the write; and
// before the writing, from the mesh's, so that a disk a neighbouring job filled meanwhile costs a
// wait for room, not the mesh. A lower bound, never an estimate: a run it stops could not have
// written its files.
#pragma once
#include <cstdint>
#include <vector>

#include "io/mesh_formats.hpp"

namespace partet {

struct MeshCounts {
  std::int64_t points = 0, tets = 0, faces = 0;  // faces: boundary triangles
};

// The fewest points and tets a mesh of a closed surface of `vertices` vertices and `faces`
// triangles can have: every input vertex stays; each face is a face of one tet (a lone tet is a
// shell of four), and each point is a corner of some tet.
MeshCounts least_mesh_counts(std::int64_t vertices, std::int64_t faces);

// The fewest bytes the files of `formats` can take for a mesh with these counts: binary arrays at
// their size; in text every row's own number with all its digits, every point id used at least
// once (so its digits too), every other value one character and its separator; the compressed
// arrays of .vtu and .pvtu sets nothing. Headers are not counted.
std::uint64_t least_output_bytes(const std::vector<MeshFormat>& formats, const MeshCounts& counts);

}  // namespace partet
