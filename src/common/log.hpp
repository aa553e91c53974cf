// One logging sink for the library and the command line: levels, a rank prefix on ranks other
// than 0, and --quiet/--verbose. Errors and warnings go to stderr, information to stdout.
#pragma once
#include <string>

namespace partet::log {

enum class Level { quiet, normal, verbose };

void set_level(Level level);
Level level();

// Another level for one scope, the previous one restored when it ends.
class ScopedLevel {
 public:
  explicit ScopedLevel(Level scoped) : saved_(level()) { set_level(scoped); }
  ~ScopedLevel() { set_level(saved_); }
  ScopedLevel(const ScopedLevel&) = delete;
  ScopedLevel& operator=(const ScopedLevel&) = delete;

 private:
  Level saved_;
};
// Lines from ranks other than 0 say which rank they come from ("partet[rank 1]: ...").
void set_rank(int rank);

void error(const std::string& message);    // "partet: error: ..." (always)
void warning(const std::string& message);  // "partet: warning: ..." (not with quiet)
void info(const std::string& message);     // "partet: ..." (not with quiet)
void debug(const std::string& message);    // "partet: ..." (verbose only)

}  // namespace partet::log
