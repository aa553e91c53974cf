// partet against TetGen alone on the same input and switches (--compare-tetgen).
#pragma once
#include <cstdint>
#include <string>

#include "job/job.hpp"
#include "job/report.hpp"
#include "stages/quality.hpp"

namespace partet {

// A run's headline figures, for the comparison with TetGen alone.
struct RunFigures {
  bool known = false;
  double seconds = 0;  // wall time
  double peak_mb = 0;  // largest process (a rank or a TetGen child)
  std::int64_t tets = 0;
  MeshQuality quality;
  std::string note;  // why the figures are missing
};

// partet's figures of a finished job (rank 0).
RunFigures run_figures(const JobSummary& summary);

// Meshes the whole input with TetGen alone (the job's switches, in a child process; nothing is
// written), after checking that it should fit in the memory available (about 2.4 KB per face,
// measured). Not with other TetGen runs at once.
RunFigures tetgen_alone(const MeshJob& job);

// The side-by-side table.
void print_comparison(const RunFigures& partet, const RunFigures& tetgen, int ranks, int pieces);

}  // namespace partet
