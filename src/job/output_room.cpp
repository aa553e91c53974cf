#include "job/output_room.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include "common/disk_space.hpp"
#include "common/log.hpp"
#include "common/paths.hpp"
#include "common/stage_timer.hpp"
#include "common/test_hooks.hpp"
#include "partet/errors.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// Room in whole MB: what is needed rounded up, what is free rounded down.
std::string megabytes_needed(double mb) { return std::to_string(static_cast<long long>(std::ceil(mb))) + " MB"; }
std::string megabytes_free(double mb) { return std::to_string(static_cast<long long>(std::floor(mb))) + " MB"; }

// How a rerun need not mesh the pieces again.
std::string rerun_advice(const MeshJob& job) {
  return job.options.run.checkpoint.empty() ? ", with --checkpoint DIR so that a rerun need not mesh the pieces again"
                                            : " with the same --checkpoint, which holds the pieces meshed";
}

// Where the output goes, as the user can find it.
std::string output_directory(const MeshJob& job) { return directory_of(absolute_path(job.output_prefix)); }

// A wait, in minutes when it is that long.
std::string wait_span(double seconds) {
  return seconds >= 60 ? std::to_string(std::lround(seconds / 60)) + " min" : std::to_string(std::lround(seconds)) + " s";
}

// The room the files of a mesh of these counts take at least, in MB.
double least_room_mb(const MeshJob& job, const MeshCounts& counts) {
  return static_cast<double>(least_output_bytes(job.formats, counts)) / 1048576.0;
}

// The room the output's filesystem has now (negative: not known).
double free_output_mb(const MeshJob& job) {
  return test_hooks::free_disk_mb(free_disk_mb(directory_of(job.output_prefix)));
}

std::int64_t used_vertex_count(const SurfaceMesh& input) {
  const std::vector<char> used = used_vertices(input.points.size(), input.triangles);
  return std::count(used.begin(), used.end(), 1);
}

}  // namespace

void refuse_output_beyond_disk(const MeshJob& job, const SurfaceMesh& input) {
  const MeshCounts least = least_mesh_counts(used_vertex_count(input), static_cast<std::int64_t>(input.triangles.size()));
  const double needed_mb = least_room_mb(job, least);
  const double free_mb = free_output_mb(job);
  if (free_mb < 0 || free_mb >= needed_mb) return;
  throw OptionError("no room for the output: the files of a mesh of these " + std::to_string(least.faces) +
                    " faces (at least " + std::to_string(least.points) + " points and " + std::to_string(least.tets) +
                    " tets) take at least " + megabytes_needed(needed_mb) + " as " + format_names(job) + ", and " +
                    output_directory(job) + " has " + megabytes_free(free_mb) +
                    " free: make room there, or write elsewhere (-o). Nothing was meshed.");
}

void wait_for_room(const MeshJob& job, const MeshCounts& counts) {
  const double needed_mb = least_room_mb(job, counts);
  const std::string where = output_directory(job);
  const double start = now_seconds(), limit = job.wait_for_space_minutes * 60;
  for (bool first = true;; first = false) {
    const double free_mb = free_output_mb(job);
    const double waited = now_seconds() - start;
    if (free_mb < 0 || free_mb >= needed_mb) {
      if (!first) log::warning("room at " + where + " after " + wait_span(waited) + ": writing");
      return;
    }
    const std::string shortfall = where + " has " + megabytes_free(free_mb) + " free, and the files of this mesh (" +
                                  std::to_string(counts.points) + " points, " + std::to_string(counts.tets) +
                                  " tets) take at least " + megabytes_needed(needed_mb) + " as " + format_names(job);
    if (waited >= limit)
      throw OutputError(shortfall + (first ? "" : ", after waiting " + wait_span(waited)) +
                        ": nothing was written; make room there and run again" + rerun_advice(job));
    if (first)
      log::warning(shortfall + ": waiting up to " + wait_span(limit) + " for room (--wait-for-space); make room there, and the files are written");
    std::this_thread::sleep_for(std::chrono::duration<double>(std::min(test_hooks::disk_poll_seconds(10), limit - waited)));
  }
}

std::string with_room_advice(const MeshJob& job, const MeshCounts& counts, const std::string& error) {
  if (error.find(std::strerror(ENOSPC)) == std::string::npos && error.find(std::strerror(EDQUOT)) == std::string::npos)
    return error;
  const double needed_mb = least_room_mb(job, counts);
  return error + " (the files of this mesh take at least " + megabytes_needed(needed_mb) + " as " + format_names(job) +
         "; make room there and run again" + rerun_advice(job) + ")";
}

}  // namespace partet
