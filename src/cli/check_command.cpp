#include "cli/check_command.hpp"

#include <mpi.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "cli/launch.hpp"
#include "cli/published_sets.hpp"
#include "common/log.hpp"
#include "common/test_hooks.hpp"
#include "io/mesh_read.hpp"
#include "io/read_surface.hpp"
#include "io/tetgen_files.hpp"
#include "mpi/collective_watch.hpp"
#include "mpi/distributed_check.hpp"
#include "partet/errors.hpp"
#include "stages/quality.hpp"
#include "stages/quality_json.hpp"

namespace partet::cli {
namespace {

// The cut planes a run's --report names. Throws InputError naming the file and the field.
std::vector<partet::CutPlane> report_cut_planes(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw partet::InputError("cannot read report '" + path + "': not a regular file");
  std::ifstream in(path);
  if (!in) throw partet::InputError("cannot open report '" + path + "'");
  const nlohmann::json report = nlohmann::json::parse(in, nullptr, false);
  if (report.is_discarded()) throw partet::InputError("report '" + path + "' is not valid JSON (a partet --report file?)");
  auto bad = [&](const std::string& field, const char* want) {
    return partet::InputError("report '" + path + "': " + field + " must be " + want);
  };
  if (!report.is_object()) throw bad("the document", "an object");
  if (!report.contains("cut_planes")) throw bad("cut_planes", "present (is this a partet --report file?)");
  const nlohmann::json& list = report["cut_planes"];
  if (!list.is_array()) throw bad("cut_planes", "a list");
  std::vector<partet::CutPlane> planes;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string at = "cut_planes[" + std::to_string(i) + "]";
    const nlohmann::json& p = list[i];
    if (!p.is_object()) throw bad(at, "an object with normal and offset");
    const nlohmann::json normal = p.value("normal", nlohmann::json());
    if (!normal.is_array() || normal.size() != 3 || !normal[0].is_number() || !normal[1].is_number() ||
        !normal[2].is_number())
      throw bad(at + ".normal", "a list of 3 numbers");
    const nlohmann::json offset = p.value("offset", nlohmann::json());
    if (!offset.is_number()) throw bad(at + ".offset", "a number");
    planes.push_back({{normal[0].get<double>(), normal[1].get<double>(), normal[2].get<double>()}, offset.get<double>()});
  }
  return planes;
}

// The quality of the seam zone and of the rest, when the run's report names the planes.
using KnownZones = std::optional<partet::ZoneQuality>;
KnownZones zone_quality(const partet::TetMesh& mesh, const std::optional<std::vector<partet::CutPlane>>& planes) {
  return planes ? KnownZones(partet::zone_quality(mesh, *planes)) : std::nullopt;
}

// The quality line and the dihedral angles' histogram.
void print_quality(const partet::MeshQuality& quality) {
  std::printf("quality: %s\n", partet::quality_line(quality).c_str());
  std::printf("dihedral angles:");
  double from = 0;
  for (std::size_t i = 0; i < partet::kDihedralBins.size(); ++i) {
    std::printf(" %g-%g: %lld%s", from, partet::kDihedralBins[i],
                static_cast<long long>(quality.dihedral_histogram[i]), i + 1 < partet::kDihedralBins.size() ? "," : "\n");
    from = partet::kDihedralBins[i];
  }
}

void print_check(const partet::CheckReport& report, const KnownZones& zones) {
  std::printf("vertices %lld, tets %lld, boundary faces %lld\n", static_cast<long long>(report.vertices),
              static_cast<long long>(report.tets), static_cast<long long>(report.boundary_faces));
  if (report.split_input_faces > 0)
    std::printf("split input triangles: %lld (tiled by boundary faces that are parts of them)\n",
                static_cast<long long>(report.split_input_faces));
  std::printf("volume: tets %.17g, surface %.17g\n", report.tet_volume, report.surface_volume);
  std::printf("euler: mesh %ld, expected %ld\n", report.euler_mesh, report.euler_expected);
  print_quality(report.quality);
  if (zones) {
    std::printf("seam zone (%lld tets): %s\n", static_cast<long long>(zones->seam.tets),
                partet::quality_line(zones->seam).c_str());
    std::printf("elsewhere (%lld tets): %s\n", static_cast<long long>(zones->elsewhere.tets),
                partet::quality_line(zones->elsewhere).c_str());
  }
  for (const auto& v : report.violations) std::printf("VIOLATION: %s\n", v.c_str());
  std::printf("%s\n", report.ok() ? "check passed" : "check FAILED");
}

// What --json prints of either check's report (a check in one process adds its own fields).
template <class Report>
nlohmann::json check_json(const Report& report) {
  return {{"ok", report.ok()},
          {"violations", report.violations},
          {"vertices", report.vertices},
          {"tets", report.tets},
          {"boundary_faces", report.boundary_faces},
          {"tet_volume", report.tet_volume},
          {"surface_volume", report.surface_volume},
          {"euler_mesh", report.euler_mesh},
          {"euler_expected", report.euler_expected},
          {"quality", partet::quality_json(report.quality)}};
}

void print_check_json(const partet::CheckReport& report, const KnownZones& zones) {
  nlohmann::json json = check_json(report);
  json["split_input_faces"] = report.split_input_faces;
  if (zones) {
    json["seam_zone_quality"] = partet::quality_json(zones->seam);
    json["elsewhere_quality"] = partet::quality_json(zones->elsewhere);
  }
  std::printf("%s\n", json.dump(2).c_str());
}

// The set to check: TetGen files at a prefix, or a set named by one of its files (mesh_read.hpp).
partet::TetgenFileSet read_set_to_check(const std::string& prefix) {
  if (!partet::reads_mesh_file(prefix)) {
    settle(prefix);
    return partet::read_tetgen_set(prefix);
  }
  settle_named(prefix);
  return partet::read_mesh_set(prefix);
}

// Every rank waits for rank 0 to settle the set (finish a publish a killed run left) before any
// reads it; under a watch, as the check's own steps, so that a rank stopped before the check
// does not hold the others here for ever.
void wait_for_settled(const std::string& path) {
  partet::test_hooks::check_start_stop(launched_rank());
  const partet::mpi::CollectiveWatch watch("checking '" + path + "'");
  MPI_Barrier(MPI_COMM_WORLD);
}

// The check on every rank of the job, each its part: an XDMF set (alone: on one rank), or under a
// launcher TetGen files or a set named by one of its files (MSH, VTK, MEDIT). Rank 0 prints.
partet::DistributedCheckReport check_on_ranks(const std::string& input_path, const std::string& path) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  std::string run;
  if (names_format(path, partet::MeshFormat::xdmf, &run)) {
    if (rank == 0) settle(run);
    wait_for_settled(run);
    return partet::check_xdmf_set(MPI_COMM_WORLD, input_path, run);
  }
  const bool named = partet::reads_mesh_file(path);
  if (rank == 0) named ? settle_named(path) : settle(path);
  wait_for_settled(path);
  return named ? partet::check_mesh_file_set(MPI_COMM_WORLD, input_path, path)
               : partet::check_tetgen_set(MPI_COMM_WORLD, input_path, path);
}

int run_check_distributed(const std::string& input_path, const std::string& path, bool json) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const partet::DistributedCheckReport report = check_on_ranks(input_path, path);
  if (rank != 0) return report.ok() ? 0 : 1;
  if (json) {
    std::printf("%s\n", check_json(report).dump(2).c_str());
  } else {
    int ranks = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    std::printf("%lld vertices, %lld tets, %lld boundary faces (checked on %d rank%s)\n",
                static_cast<long long>(report.vertices), static_cast<long long>(report.tets),
                static_cast<long long>(report.boundary_faces), ranks, ranks == 1 ? "" : "s");
    std::printf("volume %.17g (input encloses %.17g), V-E+F-T %ld (expected %ld)\n", report.tet_volume,
                report.surface_volume, report.euler_mesh, report.euler_expected);
    print_quality(report.quality);
    for (const auto& v : report.violations) std::printf("VIOLATION: %s\n", v.c_str());
    std::printf("%s\n", report.ok() ? "check passed" : "check FAILED");
  }
  return report.ok() ? 0 : 1;
}

}  // namespace

// Exit code 0 when the check passes, 1 when it fails (2 is kept for usage errors).
int run_check(const std::string& input_path, const std::string& prefix, const std::string& report_path, bool json,
              partet::BoundaryRule rule) {
  std::optional<std::vector<partet::CutPlane>> planes;  // read first: a bad report fails before the work
  if (!report_path.empty()) planes = report_cut_planes(report_path);
  const partet::TetgenFileSet files = read_set_to_check(prefix);
  const partet::CheckReport report = partet::check_mesh_files(partet::read_surface(input_path), files, rule);
  const KnownZones zones = zone_quality(files.mesh, planes);
  json ? print_check_json(report, zones) : print_check(report, zones);
  return report.ok() ? 0 : 1;
}

// partet check INPUT PREFIX.xdmf (or any set under a launcher): under MPI, each rank checking its
// part (see check_on_ranks).
int run_check_on_ranks(int argc, char** argv, const std::string& input, const std::string& path, bool json) {
  if (const std::string problem = unwritable_session_directory(); !problem.empty()) {
    partet::log::error(problem);
    return 2;
  }
  start_mpi(argc, argv);
  int code = 1;
  try {
    code = run_check_distributed(input, path, json);
  } catch (const partet::InputError& e) {
    // Every rank throws it (the ranks agree on a file that cannot be read): the first says why.
    if (launched_rank() == 0) partet::log::error(e.what());
  } catch (const std::exception& e) {
    // This rank alone (out of memory in a check step, say): the others wait for it in the
    // check's exchanges, so the job must end here, or it would wait forever.
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    partet::log::error(dynamic_cast<const std::bad_alloc*>(&e)
                           ? "out of memory on rank " + std::to_string(rank) +
                                 ": run the check on more ranks (mpirun -n N partet check ...)"
                           : std::string(e.what()) + " (on rank " + std::to_string(rank) + ")");
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  MPI_Finalize();
  return code;
}

}  // namespace partet::cli
