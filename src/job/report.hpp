// What a finished job reports: the --report JSON document and the summary lines.
#pragma once
#include <string>
#include <vector>

#include "io/output_set.hpp"
#include "job/job.hpp"

namespace partet {

// Everything the report and the summary say about a finished job.
struct JobSummary {
  const MeshJob& job;
  const SurfaceMesh& input;   // its triangles (its points may be gone once the files are written)
  std::size_t input_vertices;
  const std::vector<double>& estimated_costs;  // each piece's, as the planes balanced them
  const MeshResult& result;
  const CheckReport& check;  // with --check: its quality covers the whole mesh
  const StageTimes& times;
  const std::vector<RankStats>& ranks;
  const std::vector<PieceRecord>& pieces;  // by index
  double total_seconds;
};

// The --report JSON document.
std::string report_json(const JobSummary& summary);
// Adds the report (when asked for) to the files published with the mesh.
void add_report(OutputSet& outputs, const JobSummary& summary);
// The lines printed at the end of a successful run.
void print_summary(const JobSummary& summary);

}  // namespace partet
