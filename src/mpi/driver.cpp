#include "partet/mpi_driver.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>

#include "partet/check.hpp"
#include "partet/errors.hpp"
#include "partet/mpi_transport.hpp"
#include "partet/serialize.hpp"
#include "partet/surface_io.hpp"
#include "partet/tetgen_files.hpp"
#include "partet/validate.hpp"

namespace partet::mpi {
namespace {

constexpr int kTagPiece = 1;
constexpr int kTagResult = 2;

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double peak_rss_mb(int who) {
  rusage usage{};
  getrusage(who, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// Rank 0 tells everyone whether to go on; on failure every rank returns 1 together.
bool agree(bool ok_here, MPI_Comm comm) {
  int ok = ok_here ? 1 : 0, all = 0;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, comm);
  return all == 1;
}

// Largest piece first, each to the least loaded rank (lowest rank on ties): deterministic, and
// the result does not depend on it anyway.
std::vector<int> assign_pieces(const std::vector<PieceSurface>& pieces, int ranks) {
  std::vector<int> order(pieces.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return pieces[a].triangles.size() > pieces[b].triangles.size(); });
  std::vector<double> load(ranks, 0.0);
  std::vector<int> owner(pieces.size(), 0);
  for (int p : order) {
    const int r = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
    owner[p] = r;
    load[r] += static_cast<double>(pieces[p].triangles.size());
  }
  return owner;
}

struct RankStats {
  double tetgen_seconds = 0;
  double peak_rss_mb = 0;
  double bytes_sent = 0, bytes_received = 0;
  double pieces = 0;
  double tetgen_child_peak_rss_mb = 0;
};
constexpr int kRankStatsDoubles = 6;

// Writes the piece's closed surface as DIR/piece_<i>.off, for looking at a failing piece.
void dump_piece(const MeshJob& job, const PieceSurface& piece) {
  if (job.dump_pieces_dir.empty()) return;
  write_off(SurfaceMesh{piece.points, piece.triangles},
            job.dump_pieces_dir + "/piece_" + std::to_string(piece.index) + ".off");
}

PieceOutcome mesh_one(const MeshJob& job, const PieceSurface& piece, RankStats& stats) {
  const double t = now_seconds();
  PieceOutcome outcome;
  try {
    dump_piece(job, piece);
    outcome.result = tetrahedralize_piece(piece, job.options.tetgen);
  } catch (const std::exception& e) {
    outcome.error = e.what();
  }
  stats.tetgen_seconds += now_seconds() - t;
  stats.pieces += 1;
  return outcome;
}

enum Command : int { kDone = 0, kMeshPieces = 1 };

// Rank 0's side of one meshing round: tell the workers which pieces are theirs, send them, mesh
// its own, gather the rest. A worker receives all of its pieces before meshing, so no send of a
// piece can wait on a rank that is itself waiting to send a result.
std::vector<PieceOutcome> mesh_round_root(const MeshJob& job, const std::vector<PieceSurface>& pieces, int size,
                                          RankStats& stats, std::vector<int>& owner) {
  int command = kMeshPieces;
  MPI_Bcast(&command, 1, MPI_INT, 0, MPI_COMM_WORLD);
  int piece_count = static_cast<int>(pieces.size());
  MPI_Bcast(&piece_count, 1, MPI_INT, 0, MPI_COMM_WORLD);
  owner = assign_pieces(pieces, size);
  MPI_Bcast(owner.data(), piece_count, MPI_INT, 0, MPI_COMM_WORLD);
  for (int p = 0; p < piece_count; ++p)
    if (owner[p] != 0)
      stats.bytes_sent += static_cast<double>(send_bytes(serialize_piece(pieces[p]), owner[p], kTagPiece, MPI_COMM_WORLD));
  std::vector<PieceOutcome> outcomes(piece_count);
  for (int p = 0; p < piece_count; ++p)
    if (owner[p] == 0) outcomes[p] = mesh_one(job, pieces[p], stats);
  for (int p = 0; p < piece_count; ++p) {
    if (owner[p] == 0) continue;
    outcomes[p].error = recv_bytes(owner[p], kTagResult, MPI_COMM_WORLD);
    stats.bytes_received += static_cast<double>(outcomes[p].error.size());
    if (!outcomes[p].error.empty()) continue;
    const std::string bytes = recv_bytes(owner[p], kTagResult, MPI_COMM_WORLD);
    stats.bytes_received += static_cast<double>(bytes.size());
    outcomes[p].result = deserialize_result(bytes);
  }
  return outcomes;
}

void stop_workers() {
  int command = kDone;
  MPI_Bcast(&command, 1, MPI_INT, 0, MPI_COMM_WORLD);
}

// A worker: mesh rounds until rank 0 says done.
void worker_loop(const MeshJob& job, int rank, RankStats& stats, std::vector<int>& owner) {
  for (;;) {
    int command = kDone;
    MPI_Bcast(&command, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (command == kDone) return;
    int piece_count = 0;
    MPI_Bcast(&piece_count, 1, MPI_INT, 0, MPI_COMM_WORLD);
    owner.assign(piece_count, 0);
    MPI_Bcast(owner.data(), piece_count, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<PieceSurface> mine;
    for (int p = 0; p < piece_count; ++p) {
      if (owner[p] != rank) continue;
      const std::string bytes = recv_bytes(0, kTagPiece, MPI_COMM_WORLD);
      stats.bytes_received += static_cast<double>(bytes.size());
      mine.push_back(deserialize_piece(bytes));
    }
    // Mesh everything first, then send: rank 0 receives only after meshing its own pieces, so a
    // result sent earlier would block this rank until then.
    std::vector<std::pair<std::string, std::string>> replies;  // (error, serialized result)
    for (auto& piece : mine) {
      PieceOutcome outcome = mesh_one(job, piece, stats);
      piece = PieceSurface();  // free the surface before the result is serialized
      replies.emplace_back(outcome.error, outcome.error.empty() ? serialize_result(outcome.result) : std::string());
    }
    for (const auto& [error, bytes] : replies) {
      stats.bytes_sent += static_cast<double>(send_bytes(error, 0, kTagResult, MPI_COMM_WORLD));
      if (error.empty()) stats.bytes_sent += static_cast<double>(send_bytes(bytes, 0, kTagResult, MPI_COMM_WORLD));
    }
  }
}

}  // namespace

int run_mesh_job(const MeshJob& job) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const double job_start = now_seconds();
  StageTimes times;
  RankStats stats;
  std::string error;
  std::vector<int> owner;

  // Rank 0: read and validate.
  SurfaceMesh input;
  if (rank == 0) {
    try {
      double t0 = now_seconds();
      input = read_surface(job.input);
      times.emplace_back("read", now_seconds() - t0);
      t0 = now_seconds();
      // Self-intersections are checked per piece, in parallel, right before TetGen: a face pair
      // on opposite sides of a cut can only meet on the cut plane, where the cap's constrained
      // triangulation rejects crossing loops.
      validate_topology(input);
      const double volume = enclosed_volume(input);
      if (!(volume > 0))
        throw InputError("input is inside out: normals point inwards (enclosed volume " + std::to_string(volume) +
                         "); flip the face orientation");
      times.emplace_back("validate", now_seconds() - t0);
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  if (!agree(error.empty(), MPI_COMM_WORLD)) {
    if (rank == 0) std::fprintf(stderr, "partet: error: %s\n", error.c_str());
    return 1;
  }

  // Partition, close, mesh (rounds repeat when a cut causes trouble), merge, write.
  MeshResult result;
  CheckReport check;
  if (rank == 0) {
    try {
      const PieceMesher mesher = [&](const std::vector<PieceSurface>& pieces) {
        return mesh_round_root(job, pieces, size, stats, owner);
      };
      result = mesh_with_retries(input, job.options, mesher, &times);
    } catch (const std::exception& e) {
      error = e.what();
    }
    stop_workers();
    if (error.empty()) {
      try {
        if (job.check_output) {
          const double t0 = now_seconds();
          check = check_mesh(input, result.mesh);
          times.emplace_back("check", now_seconds() - t0);
          if (!check.ok()) error = "the result failed its own check: " + check.violations.front();
        }
        if (error.empty()) {
          const double t0 = now_seconds();
          write_tetgen_files(result.mesh, result.boundary_faces, job.output_prefix);
          times.emplace_back("write", now_seconds() - t0);
        }
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
  } else {
    worker_loop(job, rank, stats, owner);
  }

  // Per-rank figures to rank 0.
  stats.peak_rss_mb = peak_rss_mb(RUSAGE_SELF);
  stats.tetgen_child_peak_rss_mb = job.options.tetgen.isolate ? peak_rss_mb(RUSAGE_CHILDREN) : 0;
  std::vector<RankStats> all(rank == 0 ? size : 0);
  MPI_Gather(&stats, kRankStatsDoubles, MPI_DOUBLE, all.data(), kRankStatsDoubles, MPI_DOUBLE, 0, MPI_COMM_WORLD);

  const bool ok = agree(error.empty(), MPI_COMM_WORLD);
  if (rank != 0) return ok ? 0 : 1;
  if (!ok) {
    std::fprintf(stderr, "partet: error: %s\n", error.c_str());
    return 1;
  }

  const double total = now_seconds() - job_start;
  const int piece_count = result.pieces;
  if (!job.report_path.empty()) {
    nlohmann::json report;
    report["input"] = job.input;
    report["output_prefix"] = job.output_prefix;
    report["ranks"] = size;
    report["pieces"] = piece_count;
    report["pieces_requested"] = job.options.pieces;
    report["density"] = job.options.density;
    report["tetgen_quality"] = job.options.tetgen.quality;
    report["stage_seconds"] = nlohmann::json::object();
    for (const auto& [stage, seconds] : times)
      report["stage_seconds"][stage] = report["stage_seconds"].value(stage, 0.0) + seconds;
    report["total_seconds"] = total;
    report["counts"] = {{"input_vertices", input.points.size()},
                        {"input_faces", input.triangles.size()},
                        {"cut_vertices_inserted", result.cut_vertices_inserted},
                        {"cut_vertices_removed", result.removal.removed},
                        {"cap_triangles", result.cap_triangles},
                        {"output_vertices", result.mesh.points.size()},
                        {"output_tets", result.mesh.tets.size()}};
    report["retries"] = nlohmann::json::array();
    for (const auto& r : result.retries)
      report["retries"].push_back({{"attempt", r.attempt}, {"reason", r.reason}, {"planes_moved", r.planes}});
    for (int r = 0; r < size; ++r) {
      nlohmann::json pieces = nlohmann::json::array();
      for (std::size_t p = 0; p < owner.size(); ++p)
        if (owner[p] == r) pieces.push_back(p);
      report["rank"].push_back({{"rank", r},
                                {"pieces", pieces},
                                {"tetgen_seconds", all[r].tetgen_seconds},
                                {"peak_rss_mb", all[r].peak_rss_mb},
                                {"tetgen_process_peak_rss_mb", all[r].tetgen_child_peak_rss_mb},
                                {"bytes_sent", all[r].bytes_sent},
                                {"bytes_received", all[r].bytes_received}});
    }
    if (job.check_output)
      report["quality"] = {{"amips_avg", check.quality.amips_avg},
                           {"amips_max", check.quality.amips_max},
                           {"min_dihedral_deg", check.quality.min_dihedral_deg},
                           {"max_dihedral_deg", check.quality.max_dihedral_deg}};
    std::ofstream out(job.report_path);
    out << report.dump(2) << "\n";
    if (!out) std::fprintf(stderr, "partet: warning: cannot write report '%s'\n", job.report_path.c_str());
  }
  if (!job.quiet) {
    std::printf("partet: %zu faces -> %zu tets, %zu vertices; %d pieces on %d ranks; %lld cut vertices removed; %.2f s\n",
                input.triangles.size(), result.mesh.tets.size(), result.mesh.points.size(), piece_count, size,
                static_cast<long long>(result.removal.removed), total);
    std::printf("partet: stages:");
    for (const auto& [stage, seconds] : times) std::printf(" %s %.2f", stage.c_str(), seconds);
    double worst = 0;
    for (const auto& r : all) worst = std::max({worst, r.peak_rss_mb, r.tetgen_child_peak_rss_mb});
    std::printf("; peak RSS %.0f MB (largest process)\n", worst);
    if (!result.retries.empty()) std::printf("partet: recovered after %zu retries\n", result.retries.size());
    if (job.check_output)
      std::printf("partet: check passed; AMIPS avg %.3g max %.3g\n", check.quality.amips_avg, check.quality.amips_max);
    std::printf("partet: wrote %s.node/.ele/.face/.neigh\n", job.output_prefix.c_str());
  }
  return 0;
}

}  // namespace partet::mpi
