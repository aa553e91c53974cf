#include "partet/mpi_driver.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <memory>
#include <thread>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>

#include "partet/check.hpp"
#include "partet/isolated_run.hpp"
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

struct RankStats {
  double tetgen_seconds = 0;
  double peak_rss_mb = 0;
  double bytes_sent = 0, bytes_received = 0;
  double pieces = 0;
  double tetgen_child_peak_rss_mb = 0;
  double send_seconds = 0, receive_seconds = 0;  // time spent inside MPI sends and receives
};
constexpr int kRankStatsDoubles = 8;

// Writes the piece's closed surface as DIR/piece_<i>.off, for looking at a failing piece.
void dump_piece(const MeshJob& job, const PieceSurface& piece) {
  if (job.dump_pieces_dir.empty()) return;
  write_off(SurfaceMesh{piece.points, piece.triangles},
            job.dump_pieces_dir + "/piece_" + std::to_string(piece.index) + ".off");
}

// Test hook: PARTET_INJECT_FAILURE="P:error" makes piece P fail with an error, "P:abort" makes
// the process meshing piece P abort (on a worker that kills the rank, as a real crash would).
void inject_failure(int piece, int rank) {
  const char* spec = std::getenv("PARTET_INJECT_FAILURE");
  if (!spec) return;
  const std::string s(spec);
  const auto colon = s.find(':');
  if (colon == std::string::npos || std::atoi(s.substr(0, colon).c_str()) != piece) return;
  const std::string mode = s.substr(colon + 1);
  if (mode == "abort") {
    std::fprintf(stderr, "partet: rank %d: piece %d: injected abort\n", rank, piece);
    std::fflush(stderr);
    std::abort();
  }
  throw MeshingError(piece, "injected failure (PARTET_INJECT_FAILURE)");
}

// Meshes one piece; the serialized result, as it is sent to rank 0.
std::string mesh_here(const MeshJob& job, const PieceSurface& piece, int rank) {
  dump_piece(job, piece);
  if (!job.options.tetgen.isolate) {
    inject_failure(piece.index, rank);
    return tetrahedralize_piece_to_bytes(piece, job.options.tetgen);
  }
  auto run = start_piece_meshing(piece, job.options.tetgen, [&] { inject_failure(piece.index, rank); });
  return piece_meshing_result(*run, piece.index);
}

enum Command : int { kDone = 0, kMeshPieces = 1 };

// Rank 0's side of one meshing round, a dynamic master/worker queue: pieces go largest-first to
// whichever rank is free. Rank 0 meshes pieces too, in a child process it polls between MPI
// messages, so with -np 2 both cores work. Outcomes are stored by piece index, so the result does
// not depend on which rank meshed what.
std::vector<PieceOutcome> mesh_round_root(const MeshJob& job, const std::vector<PieceSurface>& pieces, int size,
                                          RankStats& stats, std::map<int, int>& owner) {
  int command = kMeshPieces;
  MPI_Bcast(&command, 1, MPI_INT, 0, MPI_COMM_WORLD);
  const int piece_count = static_cast<int>(pieces.size());
  std::vector<int> order(piece_count);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return pieces[a].triangles.size() > pieces[b].triangles.size(); });
  std::map<int, int> position;  // piece index -> position in `pieces` (a retry may send a subset)
  for (int p = 0; p < piece_count; ++p) position[pieces[p].index] = p;
  std::vector<PieceOutcome> outcomes(piece_count);
  int next = 0, remaining = piece_count;

  auto hand_out = [&](int worker) {  // the next piece, or an empty message: round over
    const double t = now_seconds();
    struct AddTime {
      double& total;
      double start;
      ~AddTime() { total += now_seconds() - start; }
    } timer{stats.send_seconds, t};
    if (next < piece_count) {
      const int p = order[next++];
      owner[pieces[p].index] = worker;
      stats.bytes_sent += static_cast<double>(send_bytes(serialize_piece(pieces[p]), worker, kTagPiece, MPI_COMM_WORLD));
    } else {
      stats.bytes_sent += static_cast<double>(send_bytes(std::string(), worker, kTagPiece, MPI_COMM_WORLD));
    }
  };
  for (int w = 1; w < size; ++w) hand_out(w);

  // Rank 0 meshes in a child it can poll only when TetGen runs isolated; otherwise it only
  // hands out work (and meshes alone when it is the only rank).
  const bool root_meshes = job.options.tetgen.isolate || size == 1;
  std::unique_ptr<IsolatedRun> own;
  int own_piece = -1;
  double own_start = 0;
  auto finish_own = [&](const std::function<std::string()>& result) {
    try {
      outcomes[own_piece].result = deserialize_result(result());
    } catch (const std::exception& e) {
      outcomes[own_piece].error = e.what();
    }
    stats.tetgen_seconds += now_seconds() - own_start;
    stats.pieces += 1;
    --remaining;
  };
  while (remaining > 0) {
    bool progress = false;
    if (root_meshes && !own && next < piece_count) {
      own_piece = order[next++];
      owner[pieces[own_piece].index] = 0;
      const PieceSurface& piece = pieces[own_piece];
      own_start = now_seconds();
      if (job.options.tetgen.isolate) {
        dump_piece(job, piece);
        own = start_piece_meshing(piece, job.options.tetgen, [&piece] { inject_failure(piece.index, 0); });
      } else {
        finish_own([&] { return mesh_here(job, piece, 0); });  // dumps the piece itself
      }
      progress = true;
    }
    if (own && own->poll(0)) {
      finish_own([&] { return piece_meshing_result(*own, pieces[own_piece].index); });
      own.reset();
      progress = true;
    }
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, kTagResult, MPI_COMM_WORLD, &arrived, &status);
    if (arrived) {
      const double t = now_seconds();
      const int worker = status.MPI_SOURCE;
      const std::string header = recv_bytes(worker, kTagResult, MPI_COMM_WORLD);  // "index\nerror"
      stats.bytes_received += static_cast<double>(header.size());
      const auto newline = header.find('\n');
      const int p = position.at(std::atoi(header.substr(0, newline).c_str()));
      outcomes[p].error = header.substr(newline + 1);
      if (outcomes[p].error.empty()) {
        const std::string bytes = recv_bytes(worker, kTagResult, MPI_COMM_WORLD);
        stats.bytes_received += static_cast<double>(bytes.size());
        outcomes[p].result = deserialize_result(bytes);
      }
      stats.receive_seconds += now_seconds() - t;
      --remaining;
      hand_out(worker);
      progress = true;
    }
    if (!progress) {
      if (own)
        own->poll(2);
      else
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  return outcomes;
}

void stop_workers() {
  int command = kDone;
  MPI_Bcast(&command, 1, MPI_INT, 0, MPI_COMM_WORLD);
}

// A worker: in each round, mesh the pieces rank 0 hands out until it sends an empty message.
void worker_loop(const MeshJob& job, int rank, RankStats& stats) {
  for (;;) {
    int command = kDone;
    MPI_Bcast(&command, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (command == kDone) return;
    double receiving = now_seconds();
    for (;;) {
      std::string bytes = recv_bytes(0, kTagPiece, MPI_COMM_WORLD);
      stats.receive_seconds += now_seconds() - receiving;
      stats.bytes_received += static_cast<double>(bytes.size());
      if (bytes.empty()) break;
      PieceSurface piece = deserialize_piece(bytes);
      std::string().swap(bytes);
      const int index = piece.index;
      const double t = now_seconds();
      std::string error, result;
      try {
        result = mesh_here(job, piece, rank);
      } catch (const std::exception& e) {
        error = e.what();
      }
      piece = PieceSurface();
      stats.tetgen_seconds += now_seconds() - t;
      stats.pieces += 1;
      const double sending = now_seconds();
      stats.bytes_sent += static_cast<double>(send_bytes(std::to_string(index) + "\n" + error, 0, kTagResult, MPI_COMM_WORLD));
      if (error.empty()) stats.bytes_sent += static_cast<double>(send_bytes(result, 0, kTagResult, MPI_COMM_WORLD));
      stats.send_seconds += now_seconds() - sending;
      receiving = now_seconds();
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
  std::map<int, int> owner;  // piece index -> rank that meshed it last

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
    worker_loop(job, rank, stats);
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
    // Rank 0's time inside the sends and receives of the meshing rounds (part of "tetgen", which
    // is the wall time of the rounds: pieces are sent, meshed and gathered concurrently).
    report["stage_seconds"]["send"] = all[0].send_seconds;
    report["stage_seconds"]["gather"] = all[0].receive_seconds;
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
      for (const auto& [piece, rank_of_piece] : owner)
        if (rank_of_piece == r && piece < piece_count) pieces.push_back(piece);
      report["rank"].push_back({{"rank", r},
                                {"pieces", pieces},
                                {"tetgen_seconds", all[r].tetgen_seconds},
                                {"peak_rss_mb", all[r].peak_rss_mb},
                                {"tetgen_process_peak_rss_mb", all[r].tetgen_child_peak_rss_mb},
                                {"bytes_sent", all[r].bytes_sent},
                                {"send_seconds", all[r].send_seconds},
                                {"receive_seconds", all[r].receive_seconds},
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
