#include "job/report.hpp"

#include "common/format.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <numeric>

#include "common/log.hpp"
#include "common/memory.hpp"
#include "io/read_surface.hpp"
#include "io/tetgen_files.hpp"
#include "partet/errors.hpp"
#include "runner/piece_runner.hpp"
#include "stages/piece_cost.hpp"
#include "stages/quality_json.hpp"
#include "stages/topology.hpp"
#include "stages/validate.hpp"

namespace partet {

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
  // Wall time during which no rank was meshing: the part more ranks cannot shorten.
  report["serial_seconds"] = s.total_seconds - s.ranks[0].meshing_wall_seconds;
  // Work done while pieces were still being meshed (inside the tetgen stage's time): welding
  // each piece's result as it arrived. stage_seconds.merge is what was left after the last one.
  report["overlapped_seconds"] = {{"merge", s.result.merge_seconds_overlapped}};
  // --scratch: the pieces' bulks that waited on disk instead of in rank 0's memory.
  report["scratch"] = {
      {"directory", s.job.options.scratch}, {"bulks", s.result.scratch_bulks}, {"bytes", s.result.scratch_bytes}};
  // The pieces split on the ranks that meshed them, whose bulks stayed there until assembled.
  report["bulks_where_meshed"] = s.result.bulks_where_meshed;
  // false: no rank held the whole mesh; the owners of its parts wrote them (the XDMF set alone).
  report["assembled_on_rank0"] = !s.result.spread;
  report["counts"] = {{"input_vertices", s.input_vertices},
                      {"input_faces", s.input.triangles.size()},
                      {"cut_vertices_inserted", s.result.cut_vertices_inserted},
                      {"cut_vertices_removed", s.result.seam.cut_vertices_removed},
                      {"cap_points_removed", s.result.seam.cap_points_removed},
                      {"seam_regions", s.result.seam.regions},
                      {"seam_chains", s.result.seam.chains},
                      {"cap_triangles", s.result.cap_triangles},
                      {"split_input_faces", s.result.split_input_faces},
                      {"surface_points_added", s.result.surface_points_added},
                      {"output_vertices", output_point_count(s.result)},
                      {"output_tets", output_tet_count(s.result)}};
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
  // What the planes balanced, for comparing with the times (scripts/bench/piece_cost.sh).
  const std::vector<double>& estimate = s.estimated_costs;
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
                              {"input_check_seconds", stats.input_check_seconds},
                              {"write_seconds", stats.write_seconds},
                              {"piece_files_written", stats.piece_files_written},
                              {"caps", stats.caps},
                              {"cap_seconds", stats.cap_seconds},
                              {"region_seconds", stats.region_seconds},
                              {"bulks_kept", stats.bulks_kept},
                              {"bulks_on_disk", stats.bulks_on_disk},
                              {"bands_grown", stats.bands_grown},
                              {"bulk_number_seconds", stats.bulk_number_seconds},
                              {"share_cut_seconds", stats.share_cut_seconds},
                              {"chain_shares_direct", stats.chain_shares_direct},
                              {"chains_kept", stats.chains_kept},
                              {"chain_tets_kept", stats.chain_tets_kept},
                              {"pieces_from_checkpoint", stats.pieces_from_checkpoint},
                              {"bytes_received", stats.bytes_received}});
  }
  report["cut_planes"] = nlohmann::json::array();
  for (const CutPlane& p : s.result.planes)
    report["cut_planes"].push_back({{"normal", p.normal}, {"offset", p.offset}});
  if (s.job.check_output) {
    // The seam zone (tets crossing or touching a cut plane) against the rest.
    const ZoneQuality zones = s.check.zones ? *s.check.zones : zone_quality(s.result.mesh, s.result.planes);
    report["quality"] = {{"all", quality_json(s.check.quality)},
                         {"seam_zone", quality_json(zones.seam)},
                         {"elsewhere", quality_json(zones.elsewhere)}};
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
  log::info(std::to_string(s.input.triangles.size()) + " faces -> " + std::to_string(output_tet_count(s.result)) +
            " tets, " + std::to_string(output_point_count(s.result)) + " vertices; " + std::to_string(s.result.pieces) +
            " pieces on " + std::to_string(s.ranks.size()) + " ranks; " +
            std::to_string(s.result.seam.cut_vertices_removed + s.result.seam.cap_points_removed) +
            " seam vertices removed; " + format("%.2f s", s.total_seconds));
  std::string stages = "stages:";
  for (const StageTime& t : s.times) stages += " " + t.stage + format(" %.2f", t.seconds);
  double worst = 0;
  for (const auto& r : s.ranks) worst = std::max({worst, r.peak_rss_mb, r.tetgen_child_peak_rss_mb});
  log::info(stages + format("; no rank meshing for %.2f s; peak RSS %.0f MB (largest process)",
                            s.total_seconds - s.ranks[0].meshing_wall_seconds, worst));
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
  if (s.result.scratch_bulks > 0)
    log::info(format("scratch: %lld pieces' meshes (%.0f MB) waited in %s",
                     static_cast<long long>(s.result.scratch_bulks),
                     static_cast<double>(s.result.scratch_bytes) / (1 << 20), s.job.options.scratch.c_str()));
  double taken = 0;
  for (const auto& r : s.ranks) taken += r.pieces_from_checkpoint;
  if (taken > 0)
    log::info(format("checkpoint: %.0f pieces taken from %s (meshed by an earlier run)", taken,
                     s.job.options.run.checkpoint.c_str()));
  if (!s.result.retries.empty()) log::info("recovered after " + std::to_string(s.result.retries.size()) + " retries");
  if (s.result.split_input_faces > 0)
    log::warning(std::to_string(s.result.split_input_faces) + " input triangles are split, into " +
                 std::to_string(output_boundary(s.result, s.input).size() - s.result.split_faces_from) + " faces by " +
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
    if (f == MeshFormat::msh_parts || f == MeshFormat::msh_parts_binary)
      written += " ... (one .msh per partition" + std::string(f == MeshFormat::msh_parts_binary ? ", binary)" : ")");
    if (f == MeshFormat::xdmf) {
      const std::vector<std::string> paths = format_paths(f, s.job.output_prefix);
      written += " (with " + paths[1] + ", " + paths[2] + " and " + paths[3] + ")";
    }
  }
  log::info("wrote " + written + (s.job.report_path.empty() ? "" : " and " + s.job.report_path));
}

}  // namespace partet
