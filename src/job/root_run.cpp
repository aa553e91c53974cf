#include "job/root_run.hpp"

#include <algorithm>
#include <cmath>

#include "common/memory.hpp"
#include "common/stage_timer.hpp"
#include "common/test_hooks.hpp"
#include "io/mesh_formats.hpp"
#include "job/output_room.hpp"
#include "io/tetgen_files.hpp"
#include "job/compare_tetgen.hpp"
#include "job/report.hpp"
#include "stages/piece_cost.hpp"

namespace partet {

RootRun::RootRun(const MeshJob& job) : job_(job), outputs_(journal_path(job.output_prefix)) {}

namespace {

// What rank 0 needs available to assemble the mesh and check it in memory (--check): it grew
// by 131 bytes per input face doing so at 22.1M faces on 2 ranks (1,375 -> 4,279 MB), with half
// as much again to spare. With less, the ranks check the files (slower, spread over the ranks).
constexpr double kAssembledCheckBytesPerFace = 200;
double assembled_check_bytes(std::size_t faces) { return kAssembledCheckBytesPerFace * static_cast<double>(faces); }

// Whether the mesh may stay where its parts are: every format is written from its parts (the
// XDMF set, a .pvtu set and the MSH partitions by their owners; TetGen's files, a .vtu, MEDIT and
// one MSH file streamed from them) and nothing must read the whole mesh on rank 0 (no comparison,
// no polish, and a check only when the ranks can read its files back: TetGen's or the XDMF set).
// With --scratch the bulks come back from their files for the writers, each to the rank that
// meshed it.
bool may_spread(const MeshJob& job) {
  return !job.formats.empty() && (!job.check_output || format_checked_on_ranks(job)) && !job.compare_tetgen &&
         !polishes(job.options) && !test_hooks::assemble_always();
}

// Why the job must check the mesh in rank 0's memory, and what the user can do instead.
std::string why_checked_in_memory(const MeshJob& job) {
  const char* instead =
      "leave out --check and write TetGen's files or the XDMF set, which `mpirun partet check` checks "
      "afterwards, each rank its part; or run where rank 0 has more memory";
  if (job.options.allow_split_faces)
    return std::string("with --allow-split-faces the mesh is checked in memory only: ") + instead;
  if (job.compare_tetgen) return std::string("--compare-tetgen assembles the mesh on rank 0: ") + instead;
  if (polishes(job.options)) return std::string("--quality assembles the mesh on rank 0 to polish it: ") + instead;
  return "the ranks read back only TetGen's files or the XDMF set, and this job writes " + format_names(job) +
         ": add --format tetgen (or xdmf), whose files every rank then checks, each its part; or leave out --check";
}

// A --check that only rank 0's memory can do is refused before the meshing when that memory is
// already short now: the run would mesh for hours, then run out of memory in the check and lose
// its result. (When the memory runs short only later, the run checks the files on the ranks if
// it writes TetGen's files or the XDMF set.)
void refuse_check_beyond_memory(const MeshJob& job, std::size_t faces) {
  if (!job.check_output || may_spread(job)) return;
  const double needed_mb = assembled_check_bytes(faces) / 1048576.0;
  const double available_mb = test_hooks::available_mb_for_check(available_memory_mb());
  if (available_mb <= 0 || available_mb >= needed_mb) return;  // (0: not known)
  throw OptionError("--check: checking the mesh of these " + std::to_string(faces) + " faces in rank 0's memory needs about " +
                    std::to_string(static_cast<long>(needed_mb)) + " MB and " +
                    std::to_string(static_cast<long>(available_mb)) + " MB are available; " +
                    why_checked_in_memory(job) + ". Nothing was meshed.");
}

}  // namespace

void RootRun::prepare(InputChecks checks) {
  check_outputs(job_);
  input_ = read_valid_input(job_.input, times_, &scale_exponent_, checks);
  refuse_check_beyond_memory(job_, input_.triangles.size());
  refuse_output_beyond_disk(job_, input_);
}

void RootRun::mesh(PieceScheduler& scheduler) {
  try {
    MeshOptions options = job_.options;
    options.spread_output = may_spread(job_);
    if (job_.check_output) options.assemble_if_available_bytes = assembled_check_bytes(input_.triangles.size());
    options.spread_neighbours = std::count(job_.formats.begin(), job_.formats.end(), MeshFormat::tetgen) > 0;
    options.spread_band = std::all_of(job_.formats.begin(), job_.formats.end(),
                                      [](MeshFormat format) { return format == MeshFormat::xdmf; });
    result_ = mesh_with_retries(input_, options, scheduler, &times_);
    scheduler.confirm_input();  // heard already, unless no piece was meshed
  } catch (...) {
    scheduler.confirm_input();  // an invalid input's own error replaces what it caused
    throw;
  }
}

void RootRun::check_and_write(const RankWriters& writers, const WrittenSetCheck& check_files) {
  scale_points(input_.points, -scale_exponent_);
  scale_points(result_.mesh.points, -scale_exponent_);
  if (SpreadMesh* spread = result_.spread.get()) {  // the owners of the other bulks scale theirs
    scale_points(spread->split_points, -scale_exponent_);
    scale_points(spread->healing_points, -scale_exponent_);
    for (SpreadBulk& bulk : spread->bulks) scale_points(bulk.block.steiner_points, -scale_exponent_);
    scale_points(spread->band_steiner_points, -scale_exponent_);
  }
  for (CutPlane& plane : result_.planes) plane.offset = std::ldexp(plane.offset, -scale_exponent_);
  // A mesh left spread is checked in its files, by every rank, before they are published.
  const bool checks_files = job_.check_output && result_.spread;
  if (!checks_files) check_ = check_result(job_, input_, result_, times_);
  // After the check only a comparison with TetGen alone reads the input's points (the mesh has
  // its own copy): 24 bytes per input vertex less while the files are written.
  input_vertices_ = input_.points.size();
  if (!job_.report_path.empty())
    estimated_costs_ = estimated_piece_costs(input_, result_.planes, job_.options.density);
  if (!job_.compare_tetgen && !checks_files) std::vector<Point3>().swap(input_.points);
  write_with_room(writers);
  if (checks_files) check_ = check_written(job_, input_, result_, outputs_, check_files, times_);
}

// A disk that fills up during the write (a neighbouring job, or files larger than the least room
// asked for) costs a wait for room, not the mesh: a failed write publishes nothing, and every
// rank still holds its part of the mesh, so the files are written again once there is room. The
// time spent waiting is a stage of its own, room_wait.
void RootRun::write_with_room(const RankWriters& writers) {
  const MeshCounts counts = written_counts();
  const double since = now_seconds();
  double waited = wait_for_room(job_, counts, since) ? now_seconds() - since : 0;
  for (;;) {
    try {
      write_result(job_, input_, result_, times_, outputs_, writers);
      break;
    } catch (const OutputError& e) {
      const double start = now_seconds();
      wait_for_more_room(job_, counts, e.what(), since);
      waited += now_seconds() - start;
    }
    if (writers.again) writers.again();
  }
  if (waited > 0) {
    times_.push_back({"room_wait", waited, current_rss_mb()});
    log_stage(times_);
  }
}

MeshCounts RootRun::written_counts() const {
  const auto faces = static_cast<std::int64_t>(input_.triangles.size());
  if (const SpreadMesh* spread = result_.spread.get()) return {spread->points, spread->tets, faces};
  return {static_cast<std::int64_t>(result_.mesh.points.size()), static_cast<std::int64_t>(result_.mesh.tets.size()),
          faces};
}

void RootRun::publish(const std::vector<RankStats>& ranks, const std::map<int, PieceRecord>& records, double seconds) {
  std::vector<PieceRecord> pieces;
  for (const auto& [index, record] : records)
    if (index < result_.pieces) pieces.push_back(record);
  const JobSummary summary{job_,   input_, input_vertices_, estimated_costs_, result_, check_,
                           times_, ranks,  pieces,          seconds};
  add_report(outputs_, summary);
  outputs_.publish();
  print_summary(summary);
  if (job_.compare_tetgen) figures_ = run_figures(summary);
}

}  // namespace partet
