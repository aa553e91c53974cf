// XDMF + HDF5 output: the XDMF files, the blocks ranks write (the HDF5 file itself is written by
// parallel_hdf5.cpp).
#include "io/xdmf.hpp"

#include <algorithm>
#include <functional>

#include "io/buffered_file.hpp"
#include "io/xml_text.hpp"
#include "partet/errors.hpp"

namespace partet {

std::pair<std::size_t, std::size_t> run_of(std::size_t n, int part, int parts) {
  const auto at = [&](int p) { return static_cast<std::size_t>((static_cast<unsigned __int128>(n) * p) / parts); };
  return {at(part), at(part + 1)};
}

namespace {

std::string data_item(const std::string& dims, const char* number_type, int precision, const std::string& h5_name,
                      const char* dataset) {
  return "<DataItem Dimensions=\"" + dims + "\" NumberType=\"" + number_type + "\" Precision=\"" +
         std::to_string(precision) + "\" Format=\"HDF\">" + xml_escaped(h5_name) + ":" + dataset + "</DataItem>";
}

std::string xdmf_document(const std::string& grid) {
  return "<?xml version=\"1.0\"?>\n<Xdmf Version=\"3.0\">\n<Domain>\n" + grid + "</Domain>\n</Xdmf>\n";
}

std::string geometry(const MeshTotals& totals, const std::string& h5_name) {
  return "<Geometry GeometryType=\"XYZ\">" + data_item(std::to_string(totals.points) + " 3", "Float", 8, h5_name, hdf5_dataset::geometry) +
         "</Geometry>\n";
}

// `cells` cells of `corners` 64-bit point ids each.
std::string topology(const char* type, std::uint64_t cells, int corners, const std::string& h5_name,
                     const char* dataset) {
  const std::string n = std::to_string(cells), k = std::to_string(corners);
  return std::string("<Topology TopologyType=\"") + type + "\" NumberOfElements=\"" + n + "\" NodesPerElement=\"" + k +
         "\">" + data_item(n + " " + k, "Int", 8, h5_name, dataset) + "</Topology>\n";
}

// One 32-bit integer per cell.
std::string cell_attribute(const char* name, std::uint64_t cells, const std::string& h5_name, const char* dataset) {
  return std::string("<Attribute Name=\"") + name + "\" AttributeType=\"Scalar\" Center=\"Cell\">" +
         data_item(std::to_string(cells), "Int", 4, h5_name, dataset) + "</Attribute>\n";
}

}  // namespace

MeshBlockView mesh_block_view(const MeshOutput& output, const std::vector<std::int32_t>& region, int part, int parts,
                              MadeColumns& made) {
  const TetMesh& mesh = output.mesh;
  MeshBlockView block;
  const auto [p0, p1] = run_of(mesh.points.size(), part, parts);
  block.points = {mesh.points.data() + p0, p1 - p0};
  const auto [t0, t1] = run_of(mesh.tets.size(), part, parts);
  block.tets = {mesh.tets.data() + t0, t1 - t0};
  block.tet_region = {region.data() + t0, t1 - t0};
  if (mesh.piece.empty()) {
    made.piece.assign(t1 - t0, -1);
    block.tet_piece = {made.piece.data(), made.piece.size()};
  } else {
    block.tet_piece = {mesh.piece.data() + t0, t1 - t0};
  }
  const auto [f0, f1] = run_of(output.boundary.size(), part, parts);
  block.faces = {output.boundary.data() + f0, f1 - f0};
  made.marker.clear();
  for (std::size_t f = f0; f < f1; ++f) made.marker.push_back(f < output.split_from ? 1 : 2);
  block.face_marker = {made.marker.data(), made.marker.size()};
  return block;
}

std::string xdmf_mesh_text(const MeshTotals& totals, const std::string& mesh_h5) {
  return xdmf_document("<Grid Name=\"mesh\" GridType=\"Uniform\">\n" +
                       topology("Tetrahedron", totals.tets, 4, mesh_h5, hdf5_dataset::topology) +
                       geometry(totals, mesh_h5) +
                       cell_attribute("region", totals.tets, mesh_h5, hdf5_dataset::region) +
                       cell_attribute("piece", totals.tets, mesh_h5, hdf5_dataset::piece) + "</Grid>\n");
}

std::string xdmf_boundary_text(const MeshTotals& totals, const std::string& mesh_h5, const std::string& boundary_h5) {
  return xdmf_document("<Grid Name=\"boundary\" GridType=\"Uniform\">\n" +
                       topology("Triangle", totals.faces, 3, boundary_h5, hdf5_dataset::faces) +
                       geometry(totals, mesh_h5) +
                       cell_attribute("boundary", totals.faces, boundary_h5, hdf5_dataset::markers) + "</Grid>\n");
}

std::vector<std::string> xdmf_paths(const std::string& prefix) {
  return {prefix + ".xdmf", prefix + "_boundary.xdmf", prefix + ".h5", prefix + "_boundary.h5"};
}

void add_xdmf_files(OutputSet& set, const MeshOutput& output, const std::string& prefix, const Hdf5Write& write_hdf5) {
  const std::vector<std::string> paths = xdmf_paths(prefix);
  MeshTotals totals;
  // Both HDF5 files are written by one call (every rank takes part once), each under its own
  // temporary name.
  set.add(paths[2], [&](const std::string& mesh_tmp) {
    set.add(paths[3], [&](const std::string& boundary_tmp) {
      totals = write_hdf5(output, Hdf5Paths{mesh_tmp, boundary_tmp, paths[2], paths[3]});
    });
  });
  // The XDMF files name the HDF5 files relative to themselves (they are beside them).
  const auto name = [](const std::string& path) { return path.substr(path.find_last_of('/') + 1); };
  const auto add_text = [&set](const std::string& path, const std::string& text) {
    set.add(path, [&](const std::string& tmp) {
      BufferedFile out(tmp, path);
      out.bytes(text.data(), text.size());
      out.close();
    });
  };
  add_text(paths[0], xdmf_mesh_text(totals, name(paths[2])));
  add_text(paths[1], xdmf_boundary_text(totals, name(paths[2]), name(paths[3])));
}

}  // namespace partet
