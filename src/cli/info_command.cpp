#include "cli/info_command.hpp"

#include <mpi.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli/launch.hpp"
#include "cli/published_sets.hpp"
#include "io/mesh_read.hpp"
#include "io/parallel_hdf5.hpp"
#include "io/read_surface.hpp"
#include "io/tetgen_files.hpp"
#include "partet/errors.hpp"
#include "stages/info.hpp"
#include "stages/quality.hpp"
#include "stages/quality_json.hpp"

namespace partet::cli {
namespace {

std::string bounds_text(const partet::Bounds& b) {
  char text[200];
  std::snprintf(text, sizeof text, "[%.6g, %.6g] x [%.6g, %.6g] x [%.6g, %.6g]", b.min[0], b.max[0], b.min[1],
                b.max[1], b.min[2], b.max[2]);
  return text;
}

nlohmann::json bounds_json(const partet::Bounds& b) { return {{"min", b.min}, {"max", b.max}}; }

int print_surface_info(const std::string& path, bool json) {
  const partet::SurfaceInfo i = partet::surface_info(partet::read_surface(path));
  const char* yes[] = {"no", "yes"};
  if (json) {
    std::printf("%s\n", nlohmann::json{{"kind", "surface"}, {"vertices", i.vertices}, {"unused_vertices", i.unused_vertices},
                                       {"faces", i.faces}, {"edges", i.edges}, {"bounds", bounds_json(i.bounds)},
                                       {"shells", i.shells}, {"euler", i.euler}, {"genus", i.genus},
                                       {"border_edges", i.border_edges}, {"non_manifold_edges", i.non_manifold_edges},
                                       {"misoriented_edges", i.misoriented_edges},
                                       {"volume", static_cast<double>(i.volume)},
                                       {"self_intersection", i.self_intersection},
                                       {"meshable", i.meshable()}}.dump(2).c_str());
    return 0;
  }
  std::printf("surface %s: %lld vertices (%lld unused), %lld faces, %lld edges\n", path.c_str(),
              static_cast<long long>(i.vertices), static_cast<long long>(i.unused_vertices),
              static_cast<long long>(i.faces), static_cast<long long>(i.edges));
  std::printf("bounds: %s\n", bounds_text(i.bounds).c_str());
  std::printf("shells %lld, Euler characteristic %lld, genus %s\n", static_cast<long long>(i.shells),
              static_cast<long long>(i.euler), i.genus < 0 ? "unknown (not closed, manifold and oriented)"
                                                            : std::to_string(i.genus).c_str());
  std::printf("closed %s (%lld border edges), manifold %s (%lld edges in 3+ faces), oriented %s (%lld edges)\n",
              yes[i.closed()], static_cast<long long>(i.border_edges), yes[i.manifold()],
              static_cast<long long>(i.non_manifold_edges), yes[i.oriented()],
              static_cast<long long>(i.misoriented_edges));
  if (i.closed() && i.oriented())
    std::printf("enclosed volume %.9Lg (%s)\n", i.volume, i.volume > 0 ? "outward" : "inside out");
  std::printf("self-intersections: %s\n", !i.self_intersection_checked ? "not checked (needs a closed, oriented surface)"
                                           : i.self_intersection.empty() ? "none"
                                                                         : i.self_intersection.c_str());
  std::printf("meshable by partet: %s\n", yes[i.meshable()]);
  return 0;
}

// A TetGen file set when FILE is PREFIX.node, PREFIX.ele or a PREFIX with PREFIX.node beside it.
bool tet_mesh_prefix(const std::string& file, std::string& prefix) {
  for (const char* ext : {".node", ".ele"}) {
    const std::string e = ext;
    if (file.size() > e.size() && file.compare(file.size() - e.size(), e.size(), e) == 0) {
      prefix = file.substr(0, file.size() - e.size());
      return true;
    }
  }
  prefix = file;
  std::error_code ec;
  return std::filesystem::exists(file + ".node", ec);  // not opened here: a FIFO would block
}

// An XDMF set's tets, read in this process (parallel HDF5 needs MPI, on one rank here).
partet::TetMesh read_xdmf_here(int argc, char** argv, const std::string& run) {
  if (const std::string problem = unwritable_session_directory(); !problem.empty()) throw partet::Error(problem);
  start_mpi(argc, argv);
  partet::MeshTotals totals;
  partet::MeshBlock block;
  try {
    block = partet::read_mesh_hdf5(MPI_COMM_SELF, run + ".h5", run + "_boundary.h5", totals);
  } catch (...) {
    MPI_Finalize();
    throw;
  }
  MPI_Finalize();
  if (block.points.size() > static_cast<std::size_t>(INT32_MAX) || block.tets.size() > static_cast<std::size_t>(INT32_MAX))
    throw partet::InputError("'" + run + ".h5' holds more than 2^31 points or tets, more than one process can "
                             "describe: check it on several ranks instead (mpirun -n N partet check INPUT " +
                             run + ".xdmf)");
  partet::TetMesh mesh;
  mesh.points = std::move(block.points);
  mesh.tets.reserve(block.tets.size());
  for (const auto& t : block.tets) {
    partet::Tet tet;
    for (int j = 0; j < 4; ++j) {
      if (t[j] < 0 || t[j] >= static_cast<std::int64_t>(mesh.points.size()))
        throw partet::InputError("'" + run + ".h5' has a tet with point " + std::to_string(t[j]) + " of " +
                                 std::to_string(mesh.points.size()));
      tet[j] = static_cast<std::int32_t>(t[j]);
    }
    mesh.tets.push_back(tet);
  }
  return mesh;
}

// The tets FILE names, its publish settled first: TetGen files at PREFIX, a file of another format
// partet writes (its set: a .pvtu index, MSH partitions), or an XDMF set.
partet::TetMesh read_tet_mesh_to_describe(int argc, char** argv, const std::string& file, const std::string& prefix) {
  std::string run;
  if (names_format(file, partet::MeshFormat::xdmf, &run)) {
    settle(run);
    return read_xdmf_here(argc, argv, run);
  }
  if (partet::reads_mesh_file(file)) {
    settle_named(file);
    return std::move(partet::read_mesh_set(file).mesh);
  }
  settle(prefix);
  return partet::read_tetgen_files(prefix);
}

int print_tet_mesh_info(const partet::TetMesh& mesh, const std::string& prefix, bool json) {
  const partet::TetMeshInfo i = partet::tet_mesh_info(mesh);
  if (json) {
    std::printf("%s\n", nlohmann::json{{"kind", "tet mesh"}, {"vertices", i.vertices}, {"tets", i.tets},
                                       {"boundary_faces", i.boundary_faces}, {"solids", i.solids},
                                       {"bounds", bounds_json(i.bounds)}, {"volume", static_cast<double>(i.volume)},
                                       {"inverted_tets", i.inverted_tets},
                                       {"quality", partet::quality_json(i.quality)}}.dump(2).c_str());
    return 0;
  }
  std::printf("tet mesh %s: %lld vertices, %lld tets, %lld boundary faces, %lld solid%s\n", prefix.c_str(),
              static_cast<long long>(i.vertices), static_cast<long long>(i.tets),
              static_cast<long long>(i.boundary_faces), static_cast<long long>(i.solids), i.solids == 1 ? "" : "s");
  std::printf("bounds: %s\n", bounds_text(i.bounds).c_str());
  std::printf("volume %.9Lg (%lld inverted or flat tets)\n", i.volume, static_cast<long long>(i.inverted_tets));
  std::printf("quality: %s\n", partet::quality_line(i.quality).c_str());
  return 0;
}

}  // namespace

int run_info(int argc, char** argv, const std::string& file, bool json) {
  std::string prefix;
  const bool tetgen = tet_mesh_prefix(file, prefix);
  if (!tetgen && !partet::reads_mesh_file(file) && !names_format(file, partet::MeshFormat::xdmf))
    return print_surface_info(file, json);
  const std::string shown = tetgen ? prefix : file;
  return print_tet_mesh_info(read_tet_mesh_to_describe(argc, argv, file, prefix), shown, json);
}

}  // namespace partet::cli
