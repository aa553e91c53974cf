#include "partet/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <unordered_map>
#include <cstdio>

#include "partet/errors.hpp"
#include "partet/validate.hpp"

#include "partet/merge.hpp"

namespace partet {
namespace {

class StageClock {
 public:
  explicit StageClock(StageTimes* times) : times_(times), start_(std::chrono::steady_clock::now()) {}
  void lap(const char* stage) {
    const auto now = std::chrono::steady_clock::now();
    if (times_) times_->emplace_back(stage, std::chrono::duration<double>(now - start_).count());
    start_ = now;
  }

 private:
  StageTimes* times_;
  std::chrono::steady_clock::time_point start_;
};

// FNV-1a over a piece's coordinates and triangles: a quick key for the retry cache (hits are
// confirmed by comparing the arrays).
std::uint64_t piece_fingerprint(const PieceSurface& piece) {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* data, std::size_t bytes) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ b[i]) * 1099511628211ull;
  };
  if (!piece.points.empty()) mix(piece.points.data(), piece.points.size() * sizeof(Point3));
  if (!piece.triangles.empty()) mix(piece.triangles.data(), piece.triangles.size() * sizeof(Triangle));
  return h;
}

}  // namespace

PreparedPieces prepare_pieces(SurfaceMesh input, const MeshOptions& options, StageTimes* times) {
  StageClock clock(times);
  PreparedPieces prepared;
  prepared.input = std::move(input);
  prepared.planes = choose_cut_planes(prepared.input, options.pieces, options.axis, options.plane_shifts);
  if (options.pieces > 1 && static_cast<int>(prepared.planes.size()) + 1 < options.pieces)
    std::fprintf(stderr,
                 "partet: warning: the model has only %zu distinct cut positions along the cut axis; "
                 "using %zu pieces instead of %d\n",
                 prepared.planes.size(), prepared.planes.size() + 1, options.pieces);
  prepared.split = split_at_planes(prepared.input, prepared.planes);
  clock.lap("partition");
  const auto caps = build_caps(prepared.split, prepared.planes, options.density);
  for (const auto& c : caps) prepared.cap_triangles += static_cast<std::int64_t>(c.triangles.size());
  prepared.pieces = assemble_pieces(prepared.split, caps);
  for (const auto& piece : prepared.pieces) check_piece_topology(piece);
  clock.lap("closure");
  return prepared;
}

MeshResult finish_mesh(const PreparedPieces& prepared, const std::vector<PieceTetMesh>& results,
                       const MeshOptions& options, StageTimes* times) {
  return finish_mesh(prepared, std::vector<PieceTetMesh>(results), options, times);
}

MeshResult finish_mesh(const PreparedPieces& prepared, std::vector<PieceTetMesh>&& results, const MeshOptions& options,
                       StageTimes* times) {
  StageClock clock(times);
  MeshResult result;
  result.mesh = weld(prepared.split.points, prepared.pieces, std::move(results));
  clock.lap("merge");
  result.removal = remove_cut_vertices(result.mesh, prepared.input, prepared.split, options.tetgen);
  clock.lap("cut_vertex_removal");

  // Input vertices keep their order; the ones no triangle uses were dropped.
  const auto& in = prepared.input;
  std::vector<std::int32_t> new_id(in.points.size(), -1);
  for (const auto& t : in.triangles)
    for (auto v : t) new_id[v] = 0;
  std::int32_t next = 0;
  for (auto& id : new_id)
    if (id == 0) id = next++;
  result.boundary_faces.reserve(in.triangles.size());
  for (const auto& t : in.triangles) result.boundary_faces.push_back({new_id[t[0]], new_id[t[1]], new_id[t[2]]});
  return result;
}

std::vector<PieceOutcome> mesh_pieces_here(const std::vector<PieceSurface>& pieces, const TetgenOptions& options) {
  std::vector<PieceOutcome> outcomes(pieces.size());
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    try {
      outcomes[p].result = tetrahedralize_piece(pieces[p], options);
    } catch (const std::exception& e) {
      outcomes[p].error = e.what();
    }
  }
  return outcomes;
}

MeshResult mesh_with_retries(const SurfaceMesh& input, const MeshOptions& options, const PieceMesher& mesher,
                             StageTimes* times) {
  MeshOptions attempt_options = options;
  attempt_options.plane_shifts.assign(options.pieces > 1 ? static_cast<std::size_t>(options.pieces) - 1 : 0, 0);
  std::vector<RetryRecord> retries;
  bool input_checked = false;
  std::unordered_map<std::uint64_t, std::pair<PieceSurface, PieceTetMesh>> meshed;  // by piece_fingerprint
  // More pieces, more cuts that can cause trouble: a few more attempts per four pieces (cheap,
  // since a retry re-meshes only the pieces it changed).
  const int attempts = std::max(1, options.max_attempts) + (std::max(options.pieces, 1) - 1) / 4;
  for (int attempt = 0;; ++attempt) {
    const bool last = attempt + 1 >= attempts;
    std::string failure;
    std::vector<int> planes_to_move;
    try {
      PreparedPieces prepared = prepare_pieces(input, attempt_options, times);
      StageClock clock(times);
      // Pieces identical to one already meshed in an earlier attempt (same points and
      // triangles in the same local order) reuse that result: a retry re-meshes only the pieces
      // its moved planes changed. TetGen is deterministic, so the output is the same either way.
      std::vector<PieceOutcome> outcomes(prepared.pieces.size());
      std::vector<PieceSurface> to_mesh;
      std::vector<std::size_t> to_mesh_index;
      std::vector<std::uint64_t> fingerprint(prepared.pieces.size());
      for (std::size_t p = 0; p < prepared.pieces.size(); ++p) {
        fingerprint[p] = piece_fingerprint(prepared.pieces[p]);
        auto hit = meshed.find(fingerprint[p]);
        if (hit != meshed.end() && hit->second.first.points == prepared.pieces[p].points &&
            hit->second.first.triangles == prepared.pieces[p].triangles) {
          outcomes[p].result = hit->second.second;
          outcomes[p].result.index = static_cast<int>(p);
        } else {
          to_mesh.push_back(prepared.pieces[p]);
          to_mesh_index.push_back(p);
        }
      }
      std::vector<PieceOutcome> fresh = mesher(to_mesh);
      for (std::size_t i = 0; i < fresh.size(); ++i) {
        const std::size_t p = to_mesh_index[i];
        outcomes[p] = std::move(fresh[i]);
      }
      std::vector<PieceOutcome>().swap(fresh);
      clock.lap("tetgen");
      for (std::size_t p = 0; p < outcomes.size(); ++p) {
        if (outcomes[p].error.empty()) continue;
        if (failure.empty()) failure = outcomes[p].error;
        if (p > 0) planes_to_move.push_back(static_cast<int>(p) - 1);
        if (p + 1 < outcomes.size()) planes_to_move.push_back(static_cast<int>(p));
      }
      if (!failure.empty() && attempt + 1 < attempts) {
        // Keep the good results for the next attempt (moved, not copied).
        for (std::size_t p = 0; p < outcomes.size(); ++p)
          if (outcomes[p].error.empty())
            meshed[fingerprint[p]] = {PieceSurface{0, {}, prepared.pieces[p].points, prepared.pieces[p].triangles},
                                      std::move(outcomes[p].result)};
      }
      if (failure.empty()) {
        decltype(meshed)().swap(meshed);
        std::vector<PieceTetMesh> results;
        results.reserve(outcomes.size());
        for (auto& o : outcomes) results.push_back(std::move(o.result));
        std::vector<PieceOutcome>().swap(outcomes);
        MeshResult result = finish_mesh(prepared, std::move(results), attempt_options, times);
        result.cut_vertices_inserted = prepared.split.cut_vertex_count();
        result.cap_triangles = prepared.cap_triangles;
        result.pieces = static_cast<int>(prepared.pieces.size());
        result.retries = std::move(retries);
        return result;
      }
    } catch (const CutRemovalError& e) {
      failure = e.what();
      planes_to_move = e.planes;
    } catch (const InputError&) {
      throw;
    } catch (const OptionError&) {
      throw;
    } catch (const Error& e) {
      failure = e.what();  // a cap or the cut-vertex removal failed: move every plane
    }
    // A self-intersection found in a piece is usually the input's own: check the whole input
    // once (throws InputError naming input faces) before blaming the cuts.
    if (failure.find("self-intersect") != std::string::npos && !input_checked) {
      check_no_self_intersections(input);
      input_checked = true;
    }
    if (planes_to_move.empty())
      for (std::size_t j = 0; j < attempt_options.plane_shifts.size(); ++j) planes_to_move.push_back(static_cast<int>(j));
    std::sort(planes_to_move.begin(), planes_to_move.end());
    planes_to_move.erase(std::unique(planes_to_move.begin(), planes_to_move.end()), planes_to_move.end());
    if (last || planes_to_move.empty()) {
      std::string advice = options.pieces > 1 ? "; try another --pieces value or --axis" : "";
      throw MeshingError(-1, failure + (attempt > 0 ? " (after " + std::to_string(attempt + 1) + " partitions)" : "") + advice);
    }
    std::fprintf(stderr, "partet: attempt %d failed: %s; moving cut plane(s)", attempt + 1, failure.c_str());
    for (int j : planes_to_move) std::fprintf(stderr, " %d", j);
    // From the third attempt on, also simplify the caps: fewer interior cap points leave TetGen
    // less to recover on the cap (the last attempt uses none).
    if (attempt >= 1 && attempt_options.density > 0) {
      attempt_options.density = attempt + 2 >= attempts ? 0.0 : attempt_options.density / 2;
      std::fprintf(stderr, " and lowering the cap density to %g", attempt_options.density);
    }
    std::fprintf(stderr, "; retrying\n");
    retries.push_back({attempt, failure, planes_to_move});
    for (int j : planes_to_move) ++attempt_options.plane_shifts[j];
  }
}

MeshResult mesh_surface(const SurfaceMesh& input, const MeshOptions& options, StageTimes* times) {
  return mesh_with_retries(
      input, options, [&](const std::vector<PieceSurface>& pieces) { return mesh_pieces_here(pieces, options.tetgen); },
      times);
}

}  // namespace partet
