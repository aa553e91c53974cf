// partet command line: mesh (MPI-aware), check, generate.
#include <mpi.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "partet/check.hpp"
#include "partet/errors.hpp"
#include "partet/generate.hpp"
#include "partet/mpi_driver.hpp"
#include "partet/surface_io.hpp"
#include "partet/tetgen_files.hpp"

namespace {

// "R" or "R/ANGLE" with positive numbers, as TetGen's -q takes it.
bool valid_quality(const std::string& q) {
  if (q.empty()) return true;
  const auto slash = q.find('/');
  auto positive = [](const std::string& s) {
    try {
      std::size_t used = 0;
      const double v = std::stod(s, &used);
      return used == s.size() && v > 0;
    } catch (...) {
      return false;
    }
  };
  if (slash == std::string::npos) return positive(q);
  return positive(q.substr(0, slash)) && positive(q.substr(slash + 1));
}

int run_check(const std::string& input_path, const std::string& prefix) {
  const partet::SurfaceMesh input = partet::read_surface(input_path);
  const partet::TetMesh mesh = partet::read_tetgen_files(prefix);
  const partet::CheckReport report = partet::check_mesh(input, mesh);
  const auto& q = report.quality;
  std::printf("vertices %lld, tets %lld, boundary faces %lld\n", static_cast<long long>(report.vertices),
              static_cast<long long>(report.tets), static_cast<long long>(report.boundary_faces));
  std::printf("volume: tets %.17g, surface %.17g\n", report.tet_volume, report.surface_volume);
  std::printf("euler: mesh %ld, expected %ld\n", report.euler_mesh, report.euler_expected);
  std::printf("quality: AMIPS avg %.4g max %.4g; dihedral min %.4g max %.4g deg; tets <5deg %lld, >175deg %lld\n",
              q.amips_avg, q.amips_max, q.min_dihedral_deg, q.max_dihedral_deg, static_cast<long long>(q.below_5deg),
              static_cast<long long>(q.above_175deg));
  for (const auto& v : report.violations) std::printf("VIOLATION: %s\n", v.c_str());
  std::printf("%s\n", report.ok() ? "check passed" : "check FAILED");
  return report.ok() ? 0 : 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"partet: distributed boundary-preserving tetrahedral meshing around TetGen"};
  app.require_subcommand(1);

  partet::mpi::MeshJob job;
  std::string quality;
  auto* mesh = app.add_subcommand("mesh", "tetrahedralize a closed surface (run under mpirun for several ranks)");
  mesh->add_option("input", job.input, "closed triangle surface (.off .obj .ply .stl)")->required();
  mesh->add_option("-o,--output", job.output_prefix, "output prefix: writes PREFIX.node .ele .face .neigh")->required();
  mesh->add_option("-k,--pieces", job.options.pieces, "number of pieces (cut planes + 1)")
      ->check(CLI::Range(1, 1 << 20))->capture_default_str();
  mesh->add_option("-d,--density", job.options.density,
                   "cap refinement: target cap edge length = mean cut-loop edge length / D; 0 = no interior cap points")
      ->check(CLI::Range(0.0, 100.0))->capture_default_str();
  mesh->add_option("-q,--quality", quality, "TetGen quality refinement R[/ANGLE] (-q); boundary stays untouched");
  std::string axis = "auto";
  mesh->add_option("--axis", axis,
                   "cut direction: auto = coordinate axis nearest the PCA axis (exactly planar caps), pca = the PCA axis")
      ->check(CLI::IsMember({"auto", "pca"}))->capture_default_str();
  mesh->add_option("--report", job.report_path, "write stage timings and counts as JSON");
  mesh->add_flag("--check", job.check_output, "verify the result (as `partet check`) before writing it");
  mesh->add_flag("--quiet", job.quiet, "print errors only");
  mesh->add_option("--dump-pieces", job.dump_pieces_dir, "write each piece's closed surface to DIR/piece_<i>.off (debugging)");

  std::string check_input, check_prefix;
  auto* check = app.add_subcommand("check", "verify a tet mesh against its input surface and print its quality");
  check->add_option("input", check_input, "the surface that was meshed")->required();
  check->add_option("prefix", check_prefix, "prefix of the .node/.ele files")->required();

  std::string shape, generate_output;
  int faces = 2000;
  auto* generate = app.add_subcommand("generate", "write a generated closed test surface");
  generate->add_option("shape", shape, "sphere, torus, genus3, nested, two_spheres")->required();
  generate->add_option("--faces", faces, "about this many triangles")->check(CLI::Range(1, 1 << 28))->capture_default_str();
  generate->add_option("-o,--output", generate_output, "output .off file")->required();

  CLI11_PARSE(app, argc, argv);

  try {
    if (*check) return run_check(check_input, check_prefix);
    if (*generate) {
      const partet::SurfaceMesh s = partet::generate_surface(shape, faces);
      partet::write_off(s, generate_output);
      std::printf("wrote %s: %zu vertices, %zu faces\n", generate_output.c_str(), s.points.size(), s.triangles.size());
      return 0;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "partet: error: %s\n", e.what());
    return 1;
  }

  // mesh
  if (!valid_quality(quality)) {
    std::fprintf(stderr, "partet: error: --quality must be R or R/ANGLE with positive numbers (got '%s')\n",
                 quality.c_str());
    return 1;
  }
  job.options.tetgen.quality = quality;
  job.options.axis = axis == "pca" ? partet::CutAxis::pca : partet::CutAxis::coordinate_near_pca;
  MPI_Init(&argc, &argv);
  int code = 1;
  try {
    code = partet::mpi::run_mesh_job(job);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "partet: error: %s\n", e.what());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  MPI_Finalize();
  return code;
}
