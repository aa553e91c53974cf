// A mesh job as the command line describes it, and the steps rank 0 runs around the pipeline:
// reading and validating the input, checking and writing the result (the report and summary are
// in report.hpp, the comparison with TetGen alone in compare_tetgen.hpp). No MPI here: the MPI
// driver calls these on rank 0.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "io/mesh_formats.hpp"
#include "io/output_set.hpp"
#include "job/pipeline.hpp"
#include "stages/check.hpp"
#include "stages/input_share.hpp"
#include "stages/quality.hpp"

namespace partet {

struct MeshJob {
  std::string input;
  std::string output_prefix;
  std::vector<MeshFormat> formats{MeshFormat::tetgen};  // what to write at output_prefix
  std::string report_path;                              // empty: no JSON report
  MeshOptions options;
  bool check_output = false;    // run check_mesh on the result before writing
  std::string dump_pieces_dir;  // non-empty: write each piece's surface there before meshing it
  bool compare_tetgen = false;  // afterwards, mesh the whole input with TetGen alone and compare
  // How long a mesh waits for room on the output's filesystem when it has less than the files
  // need at least (other ranks wait for rank 0 an hour at most: kRootSeconds).
  double wait_for_space_minutes = 20;
};

// The job's formats by name, "tetgen, xdmf" (for messages).
std::string format_names(const MeshJob& job);

// What each rank measured. Gathered to rank 0 as raw doubles, so only doubles belong here.
struct RankStats {
  double tetgen_seconds = 0;  // meshing pieces
  double peak_rss_mb = 0;
  double bytes_sent = 0, bytes_received = 0;
  double pieces = 0;
  double tetgen_child_peak_rss_mb = 0;
  double send_seconds = 0, receive_seconds = 0;  // time spent inside MPI sends and receives
  // Rank 0 only: wall time during which some rank was meshing a piece or region. The rest of
  // the run is serial: no number of ranks shortens it.
  double meshing_wall_seconds = 0;
  double input_check_seconds = 0;  // with several ranks, each rank but 0: receiving and checking its share of the input
  double write_seconds = 0;        // in the check-and-write step (rank 0 checks the mesh first; the others wait)
  double piece_files_written = 0;  // a .pvtu set's piece files this rank wrote
  double caps = 0, cap_seconds = 0;          // caps this rank triangulated, and the time it took
  double region_seconds = 0;                 // meshing the regions seam healing and the polish re-mesh
  double bulks_kept = 0, bulks_on_disk = 0;  // a worker: bulks it kept until rank 0 took them, those in --scratch
  double bulk_number_seconds = 0;            // a worker: numbering the bulks it kept in memory, before the assembly
  double pieces_from_checkpoint = 0;         // pieces taken from --checkpoint instead of meshed (in `pieces` too)
  double bands_grown = 0;  // a worker: bands of its pieces grown here by their neighbours' crossings (their bulks stayed)
  double share_cut_seconds = 0;  // a worker: cutting its shares of the seam chains from the band parts it keeps
  // A worker: the seam chains' shares it healed from that never passed through rank 0 (its own,
  // or sent straight here by the worker keeping them), one per chain and rank.
  double chain_shares_direct = 0;
  // A worker: the seam chains it healed and kept for the writers (HealOptions::keep_healed; rank 0
  // got only their points and links), and their tets.
  double chains_kept = 0, chain_tets_kept = 0;
};
constexpr int kRankStatsDoubles = 24;
static_assert(std::is_standard_layout_v<RankStats> && sizeof(RankStats) == kRankStatsDoubles * sizeof(double),
              "RankStats is gathered as kRankStatsDoubles raw doubles");

// Where and how fast one piece was meshed.
struct PieceRecord {
  int index = 0;
  int rank = 0;
  std::int64_t triangles = 0;  // of the piece's closed surface
  std::int64_t tets = 0;       // TetGen made
  double seconds = 0;          // wall time of its meshing, where it ran
  double memory_mb = 0;        // peak memory its meshing added (TetGen's own, in a child process)
};

// Inputs at any scale: multiplying coordinates by a power of two is exact, so an input far from
// unit size is meshed as a copy scaled by 2^exponent and the mesh is scaled back, bit for bit.
// The exponent is 0 for inputs already within 2^-40 .. 2^40 (most: their output is unchanged)
// and when scaling would not be exact.
int unit_scale_exponent(const SurfaceMesh& surface);
void scale_points(std::vector<Point3>& points, int exponent);

// The input's own checks (closed, manifold, oriented, outward) on its scaled copy. Throws
// InputError. Self-intersections are left to TetGen, with a check of the whole input when a
// piece fails.
void check_input(const SurfaceMesh& input);
// The verdict of check_input from the findings of its checks (one share's or all shares' merged).
void judge_input(const InputFindings& findings);

// Where check_input runs: in this process before anything else, or on another rank while this
// one partitions (only validate_indices runs here first, which the partition needs).
enum class InputChecks { here, elsewhere };

// Scales a surface to unit size (its exponent goes to *exponent) and checks it. Throws
// InputError.
void prepare_input(SurfaceMesh& input, int* exponent, InputChecks checks = InputChecks::here);

// Reads the input, scales it to unit size (its exponent goes to *exponent) and checks it.
SurfaceMesh read_valid_input(const std::string& path, StageTimes& times, int* exponent,
                             InputChecks checks = InputChecks::here);

// Every file the job will write (as far as known before the run): each format's and the report.
std::vector<std::string> output_paths(const MeshJob& job);
// Before any work: refuses an input path that names no readable surface file and output paths
// that cannot be written or collide with each other or the input (OptionError: a usage error),
// completes a publish a killed run left half done, and removes temporaries killed runs left.
void check_outputs(const MeshJob& job);

// Checks the result if asked (throws Error when the check fails).
CheckReport check_result(const MeshJob& job, const SurfaceMesh& input, const MeshResult& result, StageTimes& times);

// The files of a mesh left where its parts are, written under temporary names (each final name
// followed by `suffix`) and not published yet: with --check, every rank reads them back and
// checks them before they are published (mpi/set_check.hpp).
struct WrittenSet {
  MeshFormat format = MeshFormat::tetgen;  // TetGen's files or the XDMF set's: read by prefix
  std::string prefix, suffix;
  const SurfaceMesh* input = nullptr;
  std::vector<CutPlane> planes;  // for the quality of the seam zone
};
using WrittenSetCheck = std::function<CheckReport(const WrittenSet&)>;
// The format whose files --check reads back when the mesh is not assembled: TetGen's, else the
// XDMF set's. Empty when the job writes neither or may split input faces: rank 0 then assembles
// the mesh and checks it in memory.
std::optional<MeshFormat> format_checked_on_ranks(const MeshJob& job);
// --check of a result left spread: its files in `outputs`, read back through `check` (throws
// Error when the check fails).
CheckReport check_written(const MeshJob& job, const SurfaceMesh& input, const MeshResult& result,
                          const OutputSet& outputs, const WrittenSetCheck& check, StageTimes& times);
// Writes the mesh files under temporary names into `outputs` (published once every rank agrees);
// an XDMF set's HDF5 file, and TetGen files' lines, with the other ranks' help (writers). Reads
// only the input's triangles (the output's boundary when the numbering is the input's).
void write_result(const MeshJob& job, const SurfaceMesh& input, const MeshResult& result, StageTimes& times,
                  OutputSet& outputs, const RankWriters& writers);

}  // namespace partet
