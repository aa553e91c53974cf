#include "partet/job.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <numeric>

#include "partet/errors.hpp"
#include "partet/log.hpp"
#include "partet/piece_cost.hpp"
#include "partet/piece_runner.hpp"
#include "partet/surface_io.hpp"
#include "partet/tetgen_files.hpp"
#include "partet/validate.hpp"
#include "process/memory.hpp"
#include "quality_json.hpp"
#include "topology.hpp"

namespace partet {
namespace {

template <class... Values>
std::string format(const char* pattern, Values... values) {
  char text[256];
  std::snprintf(text, sizeof text, pattern, values...);
  return text;
}

}  // namespace


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

void prepare_input(SurfaceMesh& input, int* exponent) {
  *exponent = unit_scale_exponent(input);
  scale_points(input.points, *exponent);
  validate_topology(input);
  const double volume = enclosed_volume(input);
  if (!(volume > 0))
    throw InputError("input is inside out: normals point inwards (enclosed volume " + std::to_string(volume) +
                     "); flip the face orientation");
}

SurfaceMesh read_valid_input(const std::string& path, StageTimes& times, int* exponent) {
  StageTimer timer(&times);
  SurfaceMesh input = read_surface(path);
  timer.lap("read");
  prepare_input(input, exponent);
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
  remove_stale_temporaries(output_paths(job));
}

CheckReport check_and_write(const MeshJob& job, const SurfaceMesh& input, const MeshResult& result, StageTimes& times,
                            OutputSet& outputs) {
  CheckReport check;
  StageTimer timer(&times);
  if (job.check_output) {
    check = check_mesh(input, result.mesh,
                       result.split_input_faces > 0 ? BoundaryRule::split_allowed : BoundaryRule::exact);
    timer.lap("check");
    if (!check.ok()) throw Error("the result failed its own check: " + check.violations.front());
  }
  const MeshOutput output{result.mesh, result.boundary_faces, result.split_faces_from};
  for (MeshFormat format : job.formats) add_mesh_files(outputs, format, output, job.output_prefix);
  timer.lap("write");
  return check;
}

std::string report_json(const JobSummary& s) {
  nlohmann::json report;
  report["partet_version"] = PARTET_VERSION;
  report["input"] = s.job.input;
  report["output_prefix"] = s.job.output_prefix;
  report["output_formats"] = nlohmann::json::array();
  for (MeshFormat f : s.job.formats) report["output_formats"].push_back(mesh_format_name(f));
  report["ranks"] = s.ranks.size();
  report["pieces"] = s.result.pieces;
  report["cut_axis"] = axis_name(s.result.axis);  // the direction of the cuts that worked
  report["pieces_requested"] = s.job.options.pieces;
  report["density"] = s.job.options.density;
  report["tetgen_quality"] = s.job.options.tetgen.quality;
  report["allow_split_faces"] = s.job.options.allow_split_faces;
  report["stage_seconds"] = nlohmann::json::object();
  report["stage_rss_mb"] = nlohmann::json::object();  // rank 0's resident memory after each stage
  for (const StageTime& t : s.times) {
    report["stage_seconds"][t.stage] = report["stage_seconds"].value(t.stage, 0.0) + t.seconds;
    report["stage_rss_mb"][t.stage] = std::max(report["stage_rss_mb"].value(t.stage, 0.0), t.rss_mb);
  }
  // Rank 0's time inside the sends and receives of the meshing rounds (part of "tetgen", which
  // is the wall time of the rounds: pieces are sent, meshed and gathered concurrently).
  report["stage_seconds"]["send"] = s.ranks[0].send_seconds;
  report["stage_seconds"]["gather"] = s.ranks[0].receive_seconds;
  report["total_seconds"] = s.total_seconds;
  // Work done while pieces were still being meshed (inside the tetgen stage's time): welding
  // each piece's result as it arrived. stage_seconds.merge is what was left after the last one.
  report["overlapped_seconds"] = {{"merge", s.result.merge_seconds_overlapped}};
  report["counts"] = {{"input_vertices", s.input.points.size()},
                      {"input_faces", s.input.triangles.size()},
                      {"cut_vertices_inserted", s.result.cut_vertices_inserted},
                      {"cut_vertices_removed", s.result.seam.cut_vertices_removed},
                      {"cap_points_removed", s.result.seam.cap_points_removed},
                      {"seam_regions", s.result.seam.regions},
                      {"cap_triangles", s.result.cap_triangles},
                      {"split_input_faces", s.result.split_input_faces},
                      {"surface_points_added", s.result.surface_points_added},
                      {"output_vertices", s.result.mesh.points.size()},
                      {"output_tets", s.result.mesh.tets.size()}};
  const PolishStats& polish = s.result.polish;
  report["polish"] = {{"enabled", polishes(s.job.options)},
                      {"poor_tets_before", polish.poor_before},
                      {"poor_tets_after", polish.poor_after},
                      {"regions", polish.regions},
                      {"regions_improved", polish.improved},
                      {"regions_left", polish.left},
                      {"stopped_by_runaway", polish.ran_away},
                      {"tets_replaced", polish.tets_in},
                      {"tets_new", polish.tets_out},
                      {"min_dihedral_deg_before", polish.min_dihedral_before},
                      {"min_dihedral_deg_after", polish.min_dihedral_after},
                      {"amips_max_before", polish.amips_max_before},
                      {"amips_max_after", polish.amips_max_after}};
  report["retries"] = nlohmann::json::array();
  for (const auto& r : s.result.retries)
    report["retries"].push_back({{"attempt", r.attempt}, {"reason", r.reason}, {"planes_moved", r.planes}});
  report["piece"] = nlohmann::json::array();
  report["balance"] = s.job.options.balance == Balance::cost ? "cost" : "vertices";
  // What the planes balanced, for comparing with the times (scripts/piece_cost.sh).
  const std::vector<double> estimate = estimated_piece_costs(s.input, s.result.planes, s.job.options.density);
  for (const PieceRecord& p : s.pieces)
    report["piece"].push_back(
        {{"index", p.index},
         {"rank", p.rank},
         {"triangles", p.triangles},
         {"estimated_cost", static_cast<std::size_t>(p.index) < estimate.size() ? estimate[p.index] : 0.0},
         {"tets", p.tets},
         {"tetgen_seconds", p.seconds},
         {"tetgen_mb", p.memory_mb}});
  for (std::size_t r = 0; r < s.ranks.size(); ++r) {
    const RankStats& stats = s.ranks[r];
    std::vector<int> pieces;
    for (const PieceRecord& p : s.pieces)
      if (p.rank == static_cast<int>(r)) pieces.push_back(p.index);
    report["rank"].push_back({{"rank", r},
                              {"pieces", pieces},
                              {"tetgen_seconds", stats.tetgen_seconds},
                              {"peak_rss_mb", stats.peak_rss_mb},
                              {"tetgen_process_peak_rss_mb", stats.tetgen_child_peak_rss_mb},
                              {"bytes_sent", stats.bytes_sent},
                              {"send_seconds", stats.send_seconds},
                              {"receive_seconds", stats.receive_seconds},
                              {"bytes_received", stats.bytes_received}});
  }
  report["cut_planes"] = nlohmann::json::array();
  for (const CutPlane& p : s.result.planes)
    report["cut_planes"].push_back({{"normal", p.normal}, {"offset", p.offset}});
  if (s.job.check_output) {
    // The seam zone (tets crossing or touching a cut plane) against the rest.
    const std::vector<char> zone = seam_zone(s.result.mesh, s.result.planes);
    report["quality"] = {
        {"all", quality_json(s.check.quality)},
        {"seam_zone", quality_json(mesh_quality(s.result.mesh, [&](std::size_t t) { return zone[t] != 0; }))},
        {"elsewhere", quality_json(mesh_quality(s.result.mesh, [&](std::size_t t) { return zone[t] == 0; }))}};
  }
  return report.dump(2) + "\n";
}

void add_report(OutputSet& outputs, const JobSummary& summary) {
  const std::string& path = summary.job.report_path;
  if (path.empty()) return;
  const std::string text = report_json(summary);
  outputs.add(path, [&](const std::string& temporary) {
    std::FILE* f = std::fopen(temporary.c_str(), "wb");
    const bool ok = f && std::fwrite(text.data(), 1, text.size(), f) == text.size();
    if (f && std::fclose(f) != 0) throw OutputError("cannot write '" + path + "': " + std::strerror(errno));
    if (!ok) throw OutputError("cannot write '" + path + "': " + std::strerror(errno));
  });
}

void print_summary(const JobSummary& s) {
  const auto& mesh = s.result.mesh;
  log::info(std::to_string(s.input.triangles.size()) + " faces -> " + std::to_string(mesh.tets.size()) + " tets, " +
            std::to_string(mesh.points.size()) + " vertices; " + std::to_string(s.result.pieces) + " pieces on " +
            std::to_string(s.ranks.size()) + " ranks; " +
            std::to_string(s.result.seam.cut_vertices_removed + s.result.seam.cap_points_removed) +
            " seam vertices removed; " + format("%.2f s", s.total_seconds));
  std::string stages = "stages:";
  for (const StageTime& t : s.times) stages += " " + t.stage + format(" %.2f", t.seconds);
  double worst = 0;
  for (const auto& r : s.ranks) worst = std::max({worst, r.peak_rss_mb, r.tetgen_child_peak_rss_mb});
  log::info(stages + format("; peak RSS %.0f MB (largest process)", worst));
  const PolishStats& polish = s.result.polish;
  if (polish.poor_before > 0)
    log::info(format(
        "polish: %lld poor tets -> %lld (%lld of %lld neighbourhoods kept%s); min dihedral %.2f -> "
        "%.2f deg, AMIPS max %.1f -> %.1f",
        static_cast<long long>(polish.poor_before), static_cast<long long>(polish.poor_after),
        static_cast<long long>(polish.improved), static_cast<long long>(polish.regions),
        polish.left > 0 ? format(", %lld too large or too poor to re-mesh", static_cast<long long>(polish.left)).c_str()
                        : "",
        polish.min_dihedral_before, polish.min_dihedral_after, polish.amips_max_before, polish.amips_max_after));
  if (polish.ran_away)
    log::warning("the polish stopped: TetGen's refinement ran away in a neighbourhood (the quality bound " +
                 s.job.options.tetgen.quality + " cannot be met there)");
  if (!s.result.retries.empty()) log::info("recovered after " + std::to_string(s.result.retries.size()) + " retries");
  if (s.result.split_input_faces > 0)
    log::warning(std::to_string(s.result.split_input_faces) + " input triangles are split, into " +
                 std::to_string(s.result.boundary_faces.size() - s.result.split_faces_from) + " faces by " +
                 std::to_string(s.result.surface_points_added) +
                 " points TetGen put on the surface (--allow-split-faces); those faces have boundary marker 2 "
                 "(.face, .mesh) or physical group 3 \"split boundary\" (.msh)");
  if (s.job.check_output) {
    char text[96];
    std::snprintf(text, sizeof text, "check passed; AMIPS avg %.3g max %.3g", s.check.quality.amips_avg,
                  s.check.quality.amips_max);
    log::info(text);
  }
  std::string written;
  for (MeshFormat f : s.job.formats) {
    if (!written.empty()) written += ", ";
    written += f == MeshFormat::tetgen ? s.job.output_prefix + ".node/.ele/.face/.neigh"
                                       : format_paths(f, s.job.output_prefix).front();
    if (f == MeshFormat::pvtu) written += " (with one .vtu per piece)";
  }
  log::info("wrote " + written + (s.job.report_path.empty() ? "" : " and " + s.job.report_path));
}

RunFigures run_figures(const JobSummary& s) {
  RunFigures f;
  f.known = true;
  f.seconds = s.total_seconds;
  for (const auto& r : s.ranks) f.peak_mb = std::max({f.peak_mb, r.peak_rss_mb, r.tetgen_child_peak_rss_mb});
  f.tets = static_cast<std::int64_t>(s.result.mesh.tets.size());
  f.quality = s.job.check_output ? s.check.quality : mesh_quality(s.result.mesh);
  return f;
}

RunFigures tetgen_alone(const MeshJob& job) {
  RunFigures f;
  StageTimes times;
  int exponent = 0;
  const SurfaceMesh input = [&] {
    const log::ScopedLevel quiet(log::Level::quiet);  // partet's own run already reported reading it
    return read_valid_input(job.input, times, &exponent);
  }();
  const double need_mb = 2.4 * 1.2 * static_cast<double>(input.triangles.size()) / 1024.0;
  const double available_mb = available_memory_mb();
  if (available_mb > 0 && need_mb > available_mb) {
    f.note = format("TetGen alone would need about %.1f GB, %.1f GB are available: not run", need_mb / 1024,
                    available_mb / 1024);
    return f;
  }
  PieceSurface whole;
  whole.points = input.points;
  whole.triangles = input.triangles;
  whole.global_ids.resize(input.points.size());
  std::iota(whole.global_ids.begin(), whole.global_ids.end(), 0);
  const double start = now_seconds();
  const PieceOutcome outcome = PieceRunner(job.options.tetgen, job.options.run).mesh(whole);
  if (outcome.failure) {
    f.note = "TetGen alone failed: " + outcome.failure->message;
    return f;
  }
  f.known = true;
  f.seconds = now_seconds() - start;
  for (const StageTime& t : times) f.seconds += t.seconds;  // reading and validating count too
  f.peak_mb = outcome.memory_mb;                            // the TetGen process (this one also holds partet's own run)
  TetMesh mesh;
  mesh.points = input.points;
  append_local_mesh(outcome.result.mesh, whole.global_ids, mesh.points, mesh.tets, mesh.neighbours);
  f.tets = static_cast<std::int64_t>(mesh.tets.size());
  f.quality = mesh_quality(mesh);
  return f;
}

void print_comparison(const RunFigures& p, const RunFigures& t, int ranks, int pieces) {
  if (!t.known) {
    log::info("compare: " + t.note);
    return;
  }
  auto row = [](const char* what, const std::string& a, const std::string& b, const std::string& ratio) {
    log::info(format("  %-16s %-28s %-22s %s", what, a.c_str(), b.c_str(), ratio.c_str()));
  };
  log::info("compare: the same input and switches, TetGen alone in one process after partet:");
  row("", format("partet (%d ranks, %d pieces)", ranks, pieces), "TetGen alone", "partet / TetGen");
  row("wall s", format("%.2f", p.seconds), format("%.2f", t.seconds), format("%.3f", p.seconds / t.seconds));
  // Not a ratio: partet's figure is a whole process, TetGen's what meshing added to its process.
  row("peak MB", format("%.0f (largest process)", p.peak_mb), format("%.0f (TetGen's own)", t.peak_mb), "");
  row("tets", std::to_string(p.tets), std::to_string(t.tets), format("%.4f", double(p.tets) / double(t.tets)));
  row("AMIPS avg / max", format("%.4g / %.4g", p.quality.amips_avg, p.quality.amips_max),
      format("%.4g / %.4g", t.quality.amips_avg, t.quality.amips_max), "");
  row("dihedral min/max", format("%.3g / %.4g deg", p.quality.min_dihedral_deg, p.quality.max_dihedral_deg),
      format("%.3g / %.4g deg", t.quality.min_dihedral_deg, t.quality.max_dihedral_deg), "");
  row("radius-edge > 2", std::to_string(p.quality.radius_edge_above_2), std::to_string(t.quality.radius_edge_above_2),
      "");
}

}  // namespace partet
