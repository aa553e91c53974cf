// The public API (partet.hpp) over the pipeline and the MPI driver: options in, a validated and
// unit-scaled copy of the surface through the stages, the result scaled back.
#include "partet/partet.hpp"

#include <cmath>

#include "common/log.hpp"
#include "common/stage_timer.hpp"
#include "io/scratch_bulks.hpp"
#include "job/job.hpp"
#include "job/pipeline.hpp"
#include "mpi/driver.hpp"
#include "runner/piece_checkpoint.hpp"
#include "stages/check.hpp"

namespace partet {
namespace {

MeshOptions mesh_options(const Options& options) {
  if (options.pieces < 1) throw OptionError("pieces must be at least 1 (got " + std::to_string(options.pieces) + ")");
  MeshOptions m;
  m.pieces = options.pieces;
  m.tetgen.quality = parse_quality(options.quality);
  m.allow_split_faces = options.allow_split_faces;
  m.scratch = options.scratch;
  m.run.checkpoint = options.checkpoint;
  return m;
}

// Errors the caller can act on before any work: the scratch and checkpoint directories (rank 0's).
void check_directories(const MeshOptions& options) {
  if (!options.scratch.empty()) check_scratch_directory(options.scratch);
  if (!options.run.checkpoint.empty()) check_checkpoint_directory(options.run.checkpoint);
}

// The caller's surface, validated and scaled to unit size (the exponent goes to *exponent).
SurfaceMesh prepared(const SurfaceMesh& surface, int* exponent) {
  SurfaceMesh input = surface;
  prepare_input(input, exponent);
  return input;
}

Result result_of(MeshResult&& r, const SurfaceMesh& input, int exponent, double start) {
  scale_points(r.mesh.points, -exponent);
  Result result;
  result.report.pieces = r.pieces;
  result.report.retries = static_cast<int>(r.retries.size());
  result.report.split_input_faces = r.split_input_faces;
  result.mesh = std::move(r.mesh);
  result.boundary_faces = r.boundary_faces.empty() ? input.triangles : std::move(r.boundary_faces);
  result.split_faces_from = r.split_faces_from;
  result.report.seconds = now_seconds() - start;
  return result;
}

log::Level level_of(const Options& options) { return options.verbose ? log::Level::normal : log::Level::quiet; }

}  // namespace

Result tetrahedralize(const SurfaceMesh& surface, const Options& options) {
  const double start = now_seconds();
  const log::ScopedLevel level(level_of(options));
  const MeshOptions m = mesh_options(options);
  check_directories(m);
  int exponent = 0;
  const SurfaceMesh input = prepared(surface, &exponent);
  return result_of(mesh_surface(input, m), input, exponent, start);
}

Result tetrahedralize(const SurfaceMesh& surface, const Options& options, MPI_Comm comm) {
  const double start = now_seconds();
  const log::ScopedLevel level(level_of(options));
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  // Option and input errors are found on rank 0 before any rank starts: the driver throws them on
  // every rank, with the same type and message.
  const MeshOptions m = mesh_options(options);
  int exponent = 0;
  SurfaceMesh input;
  std::exception_ptr input_error;
  if (rank == 0) try {
      check_directories(m);
      input = prepared(surface, &exponent);
    } catch (const Error&) {
      input_error = std::current_exception();
    }
  MeshResult r = mpi::mesh_collective(input, m, comm, nullptr, input_error);
  return rank == 0 ? result_of(std::move(r), input, exponent, start) : Result{};
}

std::vector<std::string> check(const SurfaceMesh& surface, const Result& result) {
  const BoundaryRule rule =
      result.split_faces_from < result.boundary_faces.size() ? BoundaryRule::split_allowed : BoundaryRule::exact;
  return check_mesh(surface, result.mesh, rule).violations;
}

std::string version() { return PARTET_VERSION; }

}  // namespace partet
