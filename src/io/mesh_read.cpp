#include "io/mesh_read.hpp"

#include <climits>

#include "io/medit_read.hpp"
#include "io/mesh_formats.hpp"
#include "io/msh_read.hpp"
#include "io/vtu_read.hpp"
#include "partet/errors.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

bool format_of(const std::string& path, MeshFormat& format) {
  std::string prefix;
  return split_format_extension(path, format, prefix) && (format == MeshFormat::msh || format == MeshFormat::vtu ||
                                                          format == MeshFormat::pvtu || format == MeshFormat::medit);
}

MeshFormat named_format(const std::string& path) {
  MeshFormat format;
  if (!format_of(path, format)) throw InternalError("'" + path + "' names no mesh format with cells");
  return format;
}

// The whole mesh of a set, assembled from its files in one process (32-bit ids).
class SetAssembly : public MeshSink {
 public:
  explicit SetAssembly(const std::string& path) : set_("the set of '" + path + "'") {}
  // The file whose rows come next (for messages).
  void reading(const std::string& file) { file_ = file; }

  void node(MeshId id, const Point3& point) override {
    const auto at = static_cast<std::size_t>(index(id));
    if (at >= points_.size()) points_.resize(at + 1), seen_.resize(at + 1, 0);
    if (seen_[at] && points_[at] != point)
      throw InputError("'" + file_ + "' gives node " + std::to_string(id + 1) +
                       " other coordinates than an earlier file of the set");
    points_[at] = point, seen_[at] = 1;
  }
  void tet(const std::array<MeshId, 4>& ids) override {
    tets_.push_back({index(ids[0]), index(ids[1]), index(ids[2]), index(ids[3])});
  }
  void triangle(const std::array<MeshId, 3>& ids, int) override {
    triangles_.push_back({index(ids[0]), index(ids[1]), index(ids[2])});
  }

  TetgenFileSet finish(bool lists_boundary, const std::string& faces_named) {
    for (std::size_t i = 0; i < seen_.size(); ++i)
      if (!seen_[i])
        throw InputError("no file of " + set_ + " gives node " + std::to_string(i + 1) +
                         " (the nodes must be numbered from 1 to the highest without a gap)");
    given(tets_, "tet");
    given(triangles_, "triangle");
    TetgenFileSet set;
    set.mesh.points = std::move(points_);
    set.mesh.tets = std::move(tets_);
    set.mesh.neighbours = compute_neighbours(set.mesh.tets, set.mesh.points.size(), CrowdedFace::leave_open);
    set.faces = std::move(triangles_);
    set.has_faces = lists_boundary;
    set.faces_outward = lists_boundary;
    set.faces_named = faces_named;
    return set;
  }

 private:
  std::int32_t index(MeshId id) const {
    if (id < 0 || id >= INT32_MAX)
      throw InputError("'" + file_ + "' has node " + std::to_string(id + 1) +
                       ": more points than a check in one process reads; check it on several ranks (mpirun -n N "
                       "partet check ...)");
    return static_cast<std::int32_t>(id);
  }
  template <class Cell>
  void given(const std::vector<Cell>& cells, const char* what) const {
    for (const Cell& cell : cells)
      for (std::int32_t v : cell)
        if (static_cast<std::size_t>(v) >= points_.size())
          throw InputError(std::string("a ") + what + " of " + set_ + " uses node " + std::to_string(v + 1) +
                           ", which no file gives");
  }

  std::string set_, file_;
  std::vector<Point3> points_;
  std::vector<char> seen_;  // per point: some file gave it
  std::vector<Tet> tets_;
  std::vector<Triangle> triangles_;
};

}  // namespace

bool reads_mesh_file(const std::string& path) {
  MeshFormat format;
  return format_of(path, format);
}

std::string boundary_list(const std::string& path) {
  const MeshFormat format = named_format(path);
  return format == MeshFormat::msh ? "the MSH files" : format == MeshFormat::medit ? "the MEDIT file" : "";
}

std::vector<std::string> read_named_mesh_file(const std::string& path, MeshSink& sink) {
  switch (named_format(path)) {
    case MeshFormat::msh:
      return read_msh_named(path, sink);
    case MeshFormat::pvtu:
      return pvtu_files(path);
    case MeshFormat::vtu:
      read_vtu_file(path, sink, /*in_set=*/false);
      return {path};
    default:
      read_medit_file(path, sink);
      return {path};
  }
}

void read_set_file(const std::string& path, const std::string& file, MeshSink& sink) {
  if (named_format(path) == MeshFormat::pvtu)
    read_vtu_file(file, sink, /*in_set=*/true);
  else
    read_msh_file(file, sink);
}

TetgenFileSet read_mesh_set(const std::string& path) {
  SetAssembly mesh(path);
  mesh.reading(path);
  const std::vector<std::string> files = read_named_mesh_file(path, mesh);
  for (std::size_t i = 1; i < files.size(); ++i) {
    mesh.reading(files[i]);
    read_set_file(path, files[i], mesh);
  }
  const MeshFormat format = named_format(path);
  return mesh.finish(lists_boundary(path),
                     format == MeshFormat::msh ? "the MSH triangles do" : "the MEDIT triangles do");
}

}  // namespace partet
