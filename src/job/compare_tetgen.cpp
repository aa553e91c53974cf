#include "job/compare_tetgen.hpp"

#include "common/format.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <numeric>

#include "partet/errors.hpp"
#include "common/log.hpp"
#include "stages/piece_cost.hpp"
#include "runner/piece_runner.hpp"
#include "io/read_surface.hpp"
#include "io/tetgen_files.hpp"
#include "stages/validate.hpp"
#include "common/memory.hpp"
#include "stages/quality_json.hpp"
#include "stages/topology.hpp"

namespace partet {

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
  RunOptions run = job.options.run;
  run.checkpoint.clear();  // TetGen alone runs every time: its time is the comparison
  const PieceOutcome outcome = PieceRunner(job.options.tetgen, run).mesh(whole);
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
