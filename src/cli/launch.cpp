#include "cli/launch.hpp"

#include <mpi.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "common/log.hpp"

namespace partet::cli {
namespace {

// The rank an MPI launcher gave this process, as its environment says before MPI_Init (mpirun,
// a PMIx or PMI launcher, srun); null without a launcher.
const char* launcher_rank_variable() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK", "SLURM_PROCID"})
    if (const char* value = std::getenv(name)) return value;
  return nullptr;
}

// Whether MPI can make its session directory under dir: the nearest existing ancestor (it makes
// the missing ones) must be a directory this process may write.
bool session_directory_possible(std::filesystem::path dir) {
  std::error_code error;
  while (!std::filesystem::exists(dir, error) && dir.has_relative_path()) dir = dir.parent_path();
  return std::filesystem::is_directory(dir, error) && ::access(dir.c_str(), W_OK | X_OK) == 0;
}

}  // namespace

int launched_rank() {
  const char* value = launcher_rank_variable();
  return value ? std::atoi(value) : 0;
}

int launched_size() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* value = std::getenv(name)) return std::atoi(value);
  if (std::getenv("SLURM_PROCID"))  // started by srun
    if (const char* value = std::getenv("SLURM_STEP_NUM_TASKS")) return std::atoi(value);
  return 1;
}

// MPI_Init. Run alone (no launcher), the process talks only to itself: Open MPI is asked not to
// start its helper daemon (partet never spawns or connects to other jobs) and to load no network
// transport (probing for Omni-Path hardware alone sleeps about 0.1 s). Together they cost every
// one-process run about 0.35 s. A user's own settings of these parameters are kept.
void start_mpi(int& argc, char**& argv) {
  // sbatch sets SLURM_PROCID in a batch script too: a run started there directly keeps the defaults.
  if (!launcher_rank_variable()) {
    ::setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
    ::setenv("OMPI_MCA_pml", "ob1", 0);
    ::setenv("OMPI_MCA_btl", "self", 0);
  }
  MPI_Init(&argc, &argv);
}

// A usage error: one line from the first rank, exit code 2. Under a launcher the other ranks
// wait until it has said it (a barrier): one that exited first could make the launcher end the
// job before the first rank has even started, and the user would see no reason.
int usage_error(int argc, char** argv, const std::string& message) {
  if (launched_rank() == 0) partet::log::error(message);
  if (launched_size() > 1) {
    start_mpi(argc, argv);
    MPI_Barrier(MPI_COMM_WORLD);
    MPI_Finalize();
  }
  return 2;
}

// Without a launcher, MPI_Init keeps Open MPI's session files under TMPDIR (or TEMP, TMP, /tmp):
// where that cannot be written it prints a page of errors and fails. Said here in one line
// instead. Under mpirun or srun the launcher has already made that directory.
std::string unwritable_session_directory() {
  if (std::getenv("OMPI_COMM_WORLD_RANK") || std::getenv("PMIX_RANK") || std::getenv("OMPI_MCA_orte_tmpdir_base"))
    return "";
  for (const char* name : {"TMPDIR", "TEMP", "TMP"})
    if (const char* dir = std::getenv(name); dir && *dir)
      return session_directory_possible(std::filesystem::absolute(dir))
                 ? ""
                 : std::string(name) + "=" + dir + " is not a writable directory, and MPI keeps its session files " +
                       "there: set " + name + " to one that is (e.g. " + name + "=/tmp)";
  return session_directory_possible("/tmp")
             ? ""
             : "/tmp is not writable, and MPI keeps its session files there: set TMPDIR to a writable directory";
}

}  // namespace partet::cli
