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

// The room the output's filesystem has now (negative: not known). A test that sets the free
// room sets the capacity too, or leaves it unknown.
DiskRoom output_room(const MeshJob& job) {
  DiskRoom room = disk_room(directory_of(job.output_prefix));
  const double measured = room.free_mb;
  room.free_mb = test_hooks::free_disk_mb(measured);
  if (room.free_mb != measured) room.capacity_mb = -1;
  room.capacity_mb = test_hooks::disk_capacity_mb(room.capacity_mb);
  return room;
}
double free_output_mb(const MeshJob& job) { return output_room(job).free_mb; }

// Whether no room that can be made there reaches `needed_mb`: the whole disk is smaller, so a
// wait for room would last its whole span for nothing.
bool beyond_capacity(const DiskRoom& room, double needed_mb) {
  return room.capacity_mb >= 0 && room.capacity_mb < needed_mb;
}

// What ends a wait that cannot end well.
std::string whole_disk(const DiskRoom& room, const std::string& where) {
  return "the disk at " + where + " holds " + megabytes_free(room.capacity_mb) +
         " in all, so no room can be made there for them";
}

// What a write that ran out of room (of the disk, or of a quota) says as the mesh waits.
std::string write_out_of_room(const std::string& error, bool disk_full, const std::string& where, double had_mb,
                              double wait_left) {
  return (disk_full ? "the disk" : "the quota") + std::string(" ran out while the files were written (") + error +
         "); the mesh is kept: " +
         (had_mb >= 0 ? "waiting up to " + wait_span(wait_left) + " for more room at " + where + " than the " +
                            megabytes_free(had_mb) + " the write had"
                      : "trying again every minute for up to " + wait_span(wait_left)) +
         " (--wait-for-space); make room there, and the files are written";
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

bool wait_for_room(const MeshJob& job, const MeshCounts& counts, double since) {
  const double needed_mb = least_room_mb(job, counts);
  const std::string where = output_directory(job);
  const double limit = job.wait_for_space_minutes * 60;
  for (bool first = true;; first = false) {
    const DiskRoom room = output_room(job);
    const double free_mb = room.free_mb;
    const double waited = now_seconds() - since;
    if (free_mb < 0 || free_mb >= needed_mb) {
      if (!first) log::warning("room at " + where + " after " + wait_span(waited) + ": writing");
      return !first;
    }
    const std::string shortfall = where + " has " + megabytes_free(free_mb) + " free, and the files of this mesh (" +
                                  std::to_string(counts.points) + " points, " + std::to_string(counts.tets) +
                                  " tets) take at least " + megabytes_needed(needed_mb) + " as " + format_names(job);
    if (beyond_capacity(room, needed_mb))
      throw OutputError(shortfall + "; " + whole_disk(room, where) +
                        ": nothing was written; write elsewhere (-o) and run again" + rerun_advice(job));
    if (waited >= limit)
      throw OutputError(shortfall + (first ? "" : ", after waiting " + wait_span(waited)) +
                        ": nothing was written; make room there and run again" + rerun_advice(job));
    if (first)
      log::warning(shortfall + ": waiting up to " + wait_span(limit) + " for room (--wait-for-space); make room there, and the files are written");
    std::this_thread::sleep_for(std::chrono::duration<double>(std::min(test_hooks::disk_poll_seconds(10), limit - waited)));
  }
}

void wait_for_more_room(const MeshJob& job, const MeshCounts& counts, const std::string& error, double since) {
  const bool disk_full = error.find(std::strerror(ENOSPC)) != std::string::npos;
  if (!disk_full && error.find(std::strerror(EDQUOT)) == std::string::npos) throw OutputError(error);
  const double limit = job.wait_for_space_minutes * 60, start = now_seconds();
  const auto give_up = [&] {
    const double waited = now_seconds() - start;
    return OutputError(error + " (the files of this mesh take at least " + megabytes_needed(least_room_mb(job, counts)) +
                       " as " + format_names(job) + (waited >= 1 ? "; waited " + wait_span(waited) + " for room" : "") +
                       ": nothing was written; make room there and run again" + rerun_advice(job) + ")");
  };
  if (start - since >= limit) throw give_up();
  // The failed write's files are gone, so the room now is about the room it had: writing again
  // pays only with more. A quota's room does not show, nor does an unknown filesystem's: then
  // the write is tried again after a minute.
  const DiskRoom room = disk_full ? output_room(job) : DiskRoom();
  const double had_mb = room.free_mb;
  const double enough_mb = had_mb + std::max(1.0, had_mb / 100);
  const std::string where = output_directory(job);
  if (had_mb >= 0 && beyond_capacity(room, enough_mb))
    throw OutputError(error + " (the files of this mesh take more than the " + megabytes_free(had_mb) +
                      " the write had, and " + whole_disk(room, where) +
                      ": nothing was written; write elsewhere (-o) and run again" + rerun_advice(job) + ")");
  log::warning(write_out_of_room(error, disk_full, where, had_mb, limit - (start - since)));
  const double poll = test_hooks::disk_poll_seconds(had_mb >= 0 ? 10 : 60);
  for (;;) {
    const double left = limit - (now_seconds() - since);
    if (left <= 0) throw give_up();
    std::this_thread::sleep_for(std::chrono::duration<double>(std::min(poll, left)));
    if (had_mb >= 0 && free_output_mb(job) < enough_mb) continue;
    const std::string waited = wait_span(now_seconds() - start);
    log::warning(had_mb >= 0 ? "more room at " + where + " after " + waited + ": writing again"
                             : "writing again after " + waited);
    return;
  }
}

}  // namespace partet
