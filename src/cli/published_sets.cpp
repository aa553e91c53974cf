#include "cli/published_sets.hpp"

#include "common/log.hpp"
#include "io/output_set.hpp"

namespace partet::cli {
namespace {

// An MSH file PATH's run (PATH without .msh) may have been published at RUN or, for a partition
// file PREFIX_i.msh, at PREFIX.
void settle_msh(const std::string& path, const std::string& run) {
  settle(run);
  if (std::string parts; partet::partition_file_prefix(path, parts)) settle(parts);
}

}  // namespace

void settle(const std::string& prefix) {
  if (const std::string done = partet::settle_publish(prefix); !done.empty()) partet::log::warning(done);
}

bool names_format(const std::string& path, MeshFormat format, std::string* run) {
  partet::MeshFormat named;
  std::string without;
  if (!partet::split_format_extension(path, named, without) || named != format) return false;
  if (run) *run = without;
  return true;
}

void settle_named(const std::string& path) {
  partet::MeshFormat format;
  std::string run;
  partet::split_format_extension(path, format, run);
  format == partet::MeshFormat::msh ? settle_msh(path, run) : settle(run);
}

}  // namespace partet::cli
