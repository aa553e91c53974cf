// The story of a mesh job on rank 0, its steps in the order they run, numbered as in the
// README's Method. The MPI driver calls them between its agreements and supplies where pieces
// are meshed; nothing here knows of MPI.
#pragma once
#include <map>
#include <vector>

#include "common/stage_timer.hpp"
#include "io/output_set.hpp"
#include "io/output_size.hpp"
#include "job/compare_tetgen.hpp"
#include "job/job.hpp"
#include "job/pipeline.hpp"
#include "stages/check.hpp"

namespace partet {

class RootRun {
 public:
  explicit RootRun(const MeshJob& job);

  // 1. Where the output goes: usage errors (OptionError) before any work; a publish a killed run
  //    left half done is completed, stale temporaries removed.
  // 2. The input: read, validated (closed, manifold, oriented) and scaled to unit size; refused
  //    when rank 0 has too little memory for a --check only it can do, or the output's
  //    filesystem too little room for the smallest files its mesh can have. With
  //    InputChecks::elsewhere, the driver has another rank check it (check_input) and reports
  //    the verdict through the scheduler's confirm_input.
  void prepare(InputChecks checks = InputChecks::here);
  const SurfaceMesh& input() const { return input_; }  // whole until check_and_write
  // 3-8. Partition, closure, meshing (on the scheduler's ranks), merge, seam healing and polish,
  //      with the retries of mesh_with_retries.
  void mesh(PieceScheduler& scheduler);
  // 9. Back to the input's own scale (exactly); the result checked (--check), room for its files
  //    waited for when the filesystem filled up meanwhile (--wait-for-space), and written under
  //    temporary names (an XDMF set's HDF5 file and TetGen files' lines through `writers`, which
  //    the driver has every rank take part in). A mesh left spread is checked after the write,
  //    in its files, through `check_files` (every rank reads its part).
  void check_and_write(const RankWriters& writers, const WrittenSetCheck& check_files = {});
  // 10. Once every rank has agreed: the report joins the files, the set is published, the summary
  //     printed. `pieces` says where each piece was meshed (by index).
  void publish(const std::vector<RankStats>& ranks, const std::map<int, PieceRecord>& pieces, double seconds);

  const MeshResult& result() const { return result_; }
  // The input was meshed scaled by 2^scale_exponent() (prepare).
  int scale_exponent() const { return scale_exponent_; }
  // The figures for --compare-tetgen (after publish).
  RunFigures figures() const { return figures_; }

 private:
  MeshCounts written_counts() const;  // the mesh's, for the room its files need
  void write_with_room(const RankWriters& writers);

  const MeshJob& job_;
  StageTimes times_;
  SurfaceMesh input_;  // its points only until the files are written (check_and_write)
  std::size_t input_vertices_ = 0;
  std::vector<double> estimated_costs_;  // each piece's (for the report), before the points go
  int scale_exponent_ = 0;  // the input is meshed scaled by 2^scale_exponent_
  MeshResult result_;
  CheckReport check_;
  OutputSet outputs_;  // under temporary names until every rank agrees
  RunFigures figures_;
};

}  // namespace partet
