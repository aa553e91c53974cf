#include "common/log.hpp"

#include <unistd.h>

#include <cstdio>

#include "common/stage_timer.hpp"
#include "common/memory.hpp"

namespace partet::log {
namespace {

Level g_level = Level::normal;
int g_rank = 0;

void emit(std::FILE* stream, const char* kind, const std::string& message) {
  const std::string who = g_rank == 0 ? "partet" : "partet[rank " + std::to_string(g_rank) + "]";
  std::fprintf(stream, "%s: %s%s\n", who.c_str(), kind, message.c_str());
  std::fflush(stream);
}

}  // namespace

void set_level(Level level) { g_level = level; }
Level level() { return g_level; }
void set_rank(int rank) { g_rank = rank; }

void error(const std::string& message) { emit(stderr, "error: ", message); }
void warning(const std::string& message) {
  if (g_level != Level::quiet) emit(stderr, "warning: ", message);
}
void info(const std::string& message) {
  if (g_level != Level::quiet) emit(stdout, "", message);
}
void debug(const std::string& message) {
  if (g_level == Level::verbose) emit(stdout, "", message);
}

}  // namespace partet::log

namespace partet {

void log_stage(const StageTimes& times) {
  if (times.empty()) return;
  double total = 0;
  for (const StageTime& t : times) total += t.seconds;
  char line[160];
  std::snprintf(line, sizeof line, "%s done: %.2f s (%.1f s so far, %.0f MB)", times.back().stage.c_str(),
                times.back().seconds, total, times.back().rss_mb);
  log::info(line);
}

}  // namespace partet
