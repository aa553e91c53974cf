#include "job/job.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "common/log.hpp"
#include "common/parallel.hpp"
#include "io/read_surface.hpp"
#include "io/scratch_bulks.hpp"
#include "io/tetgen_files.hpp"
#include "partet/errors.hpp"
#include "runner/piece_checkpoint.hpp"
#include "stages/topology.hpp"
#include "stages/validate.hpp"

namespace partet {

std::string format_names(const MeshJob& job) {
  std::string names;
  for (MeshFormat format : job.formats) names += (names.empty() ? "" : ", ") + mesh_format_name(format);
  return names;
}

int unit_scale_exponent(const SurfaceMesh& surface) {
  double largest = 0;
  for (const Triangle& t : surface.triangles)
    for (std::int32_t v : t)
      for (double x : surface.points[v]) largest = std::max(largest, std::abs(x));
  if (!(largest > 0) || !std::isfinite(largest)) return 0;
  const int magnitude = std::ilogb(largest);
  if (magnitude >= -40 && magnitude <= 40) return 0;
  const int exponent = -magnitude;
  for (const Triangle& t : surface.triangles)
    for (std::int32_t v : t)
      for (double x : surface.points[v])
        if (std::ldexp(std::ldexp(x, exponent), -exponent) != x) return 0;  // would lose bits
  return exponent;
}

void scale_points(std::vector<Point3>& points, int exponent) {
  if (exponent == 0) return;
  for (Point3& p : points)
    for (double& x : p) x = std::ldexp(x, exponent);
}

void check_input(const SurfaceMesh& input) {
  validate_indices(input);
  // A large input is checked in shares, one per usable CPU, as other ranks check it with MPI.
  constexpr std::size_t kFacesPerShare = std::size_t(1) << 18;
  const auto shares = static_cast<int>(std::min<std::size_t>(usable_cpus(), input.triangles.size() / kFacesPerShare));
  judge_input(check_whole(input, shares));
}

void judge_input(const InputFindings& findings) {
  throw_first_problem(findings, "input");
  const auto volume = static_cast<double>(findings.six_volume / 6);
  if (!(volume > 0))
    throw InputError("input is inside out: normals point inwards (enclosed volume " + std::to_string(volume) +
                     "); flip the face orientation");
}

void prepare_input(SurfaceMesh& input, int* exponent, InputChecks checks) {
  validate_indices(input);  // the scale looks at every face's coordinates
  *exponent = unit_scale_exponent(input);
  scale_points(input.points, *exponent);
  if (checks == InputChecks::here) check_input(input);
}

SurfaceMesh read_valid_input(const std::string& path, StageTimes& times, int* exponent, InputChecks checks) {
  StageTimer timer(&times);
  SurfaceMesh input = read_surface(path);
  timer.lap("read");
  prepare_input(input, exponent, checks);
  timer.lap("validate");
  return input;
}

std::vector<std::string> output_paths(const MeshJob& job) {
  std::vector<std::string> paths;
  for (MeshFormat format : job.formats)
    for (const std::string& path : format_paths(format, job.output_prefix)) paths.push_back(path);
  if (!job.report_path.empty()) paths.push_back(job.report_path);
  return paths;
}

void check_outputs(const MeshJob& job) {
  // "" or "out/" would write hidden files such as out/.node.
  const std::string& prefix = job.output_prefix;
  const std::string name = prefix.substr(prefix.find_last_of('/') + 1);
  if (name.empty() || name == "." || name == "..")
    throw OptionError("the output prefix '" + prefix +
                      "' names no file (give e.g. 'out/model' for out/model.node ...)");
  try {
    check_surface_path(job.input);
  } catch (const InputError& e) {
    throw OptionError(e.what());  // the command line names no usable input
  }
  check_output_paths(output_paths(job), {job.input});
  // A publish at this prefix that a killed run left half done is completed first.
  if (const std::string done = settle_publish(prefix); !done.empty()) log::warning(done);
  std::vector<FileFamily> families;
  for (MeshFormat format : job.formats)
    for (FileFamily& family : mesh_named_files(format, prefix)) families.push_back(std::move(family));
  remove_stale_temporaries(output_paths(job), families);
  if (!job.options.scratch.empty()) {
    check_scratch_directory(job.options.scratch);
    remove_stale_scratch(job.options.scratch);
  }
  if (!job.options.run.checkpoint.empty()) check_checkpoint_directory(job.options.run.checkpoint);
}

CheckReport check_result(const MeshJob& job, const SurfaceMesh& input, const MeshResult& result, StageTimes& times) {
  CheckReport check;
  if (!job.check_output) return check;
  StageTimer timer(&times);
  check =
      check_mesh(input, result.mesh, result.split_input_faces > 0 ? BoundaryRule::split_allowed : BoundaryRule::exact);
  timer.lap("check");
  if (!check.ok()) throw Error("the result failed its own check: " + check.violations.front());
  return check;
}

std::optional<MeshFormat> format_checked_on_ranks(const MeshJob& job) {
  if (job.options.allow_split_faces) return std::nullopt;  // the check on ranks knows the exact rule only
  for (MeshFormat format : {MeshFormat::tetgen, MeshFormat::xdmf})
    if (std::count(job.formats.begin(), job.formats.end(), format)) return format;
  return std::nullopt;
}

CheckReport check_written(const MeshJob& job, const SurfaceMesh& input, const MeshResult& result,
                          const OutputSet& outputs, const WrittenSetCheck& check, StageTimes& times) {
  const std::optional<MeshFormat> format = format_checked_on_ranks(job);
  if (!format || !check) throw InternalError("the mesh was left spread with no way to check its files");
  StageTimer timer(&times);
  CheckReport report = check({*format, job.output_prefix, outputs.temporary_name_suffix(), &input, result.planes});
  timer.lap("check");
  if (!report.ok()) throw Error("the result failed its own check: " + report.violations.front());
  return report;
}

void write_result(const MeshJob& job, const SurfaceMesh& input, const MeshResult& result, StageTimes& times,
                  OutputSet& outputs, const RankWriters& writers) {
  StageTimer timer(&times);
  const MeshOutput output{result.mesh, output_boundary(result, input), result.split_faces_from};
  for (MeshFormat format : job.formats) add_mesh_files(outputs, format, output, job.output_prefix, writers);
  outputs.finish_writes();  // the last file's writes belong to this stage too
  timer.lap("write");
}

}  // namespace partet
