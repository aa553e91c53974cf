#include "mpi/set_check.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <new>
#include <optional>
#include <string>
#include <vector>

#include "common/log.hpp"
#include "common/test_hooks.hpp"
#include "mpi/collective_watch.hpp"
#include "mpi/distributed_check.hpp"
#include "mpi/ranks.hpp"
#include "mpi/write_messages.hpp"
#include "partet/errors.hpp"

namespace partet::mpi {
namespace {

// The check, by the ranks that can open the set's first file (rank 0, which wrote it, always
// can): a rank on another node than a directory local to rank 0's sits it out.
std::optional<DistributedCheckReport> check_set(MeshFormat format, const UnpublishedSet& set) {
  const std::string first = set.prefix + (format == MeshFormat::xdmf ? ".h5" : ".node") + set.suffix;
  const int fd = test_hooks::output_unseen(my_rank()) ? -1 : ::open(first.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd >= 0) ::close(fd);
  MPI_Comm comm = MPI_COMM_NULL;
  test_hooks::check_start_stop(my_rank());
  {
    // Every rank of the job must join (the check's own steps are watched in the check).
    const CollectiveWatch watch("checking the mesh's files (--check)");
    MPI_Comm_split(job_comm(), fd >= 0 || my_rank() == 0 ? 0 : MPI_UNDEFINED, my_rank(), &comm);
  }
  if (comm == MPI_COMM_NULL) {
    log::warning("rank " + std::to_string(my_rank()) + " cannot open " + first +
                 " (a directory rank 0's node does not share with it?): the other ranks check the files");
    return std::nullopt;
  }
  struct Freed {
    MPI_Comm& comm;
    ~Freed() { MPI_Comm_free(&comm); }
  } freed{comm};
  try {
    return format == MeshFormat::xdmf ? check_unpublished_xdmf_set(comm, set) : check_unpublished_tetgen_set(comm, set);
  } catch (const InputError&) {
    throw;  // every rank's (the ranks agree on a file that cannot be read)
  } catch (const std::exception& e) {
    // This rank alone (out of memory in a check step, say): the others wait for it in the
    // check's exchanges, so the job ends here. The files were not published.
    abort_job(std::string(dynamic_cast<const std::bad_alloc*>(&e) ? "out of memory" : e.what()) + " on rank " +
              std::to_string(my_rank()) + " while checking the mesh's files (--check); nothing was published");
  }
}

CheckReport as_check_report(DistributedCheckReport found) {
  CheckReport report;
  report.violations = std::move(found.violations);
  report.vertices = found.vertices, report.tets = found.tets, report.boundary_faces = found.boundary_faces;
  report.tet_volume = found.tet_volume, report.surface_volume = found.surface_volume;
  report.euler_mesh = found.euler_mesh, report.euler_expected = found.euler_expected;
  report.quality = found.quality;
  report.zones = found.zones;
  return report;
}

}  // namespace

CheckReport check_on_every_rank(const WrittenSet& written) {
  UnpublishedSet set{absolute_or_error(written.prefix), written.suffix, written.input, written.planes};
  broadcast_text(std::string(kSetCheckOrder) + '\n' + mesh_format_name(written.format) + '\n' + set.prefix + '\n' +
                 set.suffix + '\n');
  broadcast_text(std::string(bytes_of(run_of(set.planes))));
  return as_check_report(*check_set(written.format, set));
}

void join_set_check(std::istringstream& order, JobStatus& status) {
  std::string format_name;
  UnpublishedSet set;
  std::getline(order, format_name), std::getline(order, set.prefix), std::getline(order, set.suffix);
  set.planes = values_of<CutPlane>(broadcast_text("")).value_or(std::vector<CutPlane>());
  try {
    check_set(mesh_format(format_name), set);
  } catch (const InputError& e) {
    status.error = e.what();  // rank 0 has the same error (the check's errors are every rank's) and reports it
  }
}

}  // namespace partet::mpi
