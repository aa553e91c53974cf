// The HDF5 file of an XDMF set, written collectively: every rank its own rows at once through
// parallel HDF5 (MPI-IO). The only file that includes hdf5.h.
#include "io/parallel_hdf5.hpp"

#include <hdf5.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <functional>
#include <type_traits>
#include <vector>

#include "common/disk_space.hpp"
#include "partet/errors.hpp"

namespace partet {
namespace {

// Rows per collective write call at most: MPI-IO counts are int, and one call per 256 MB keeps
// every transfer far below 2 GiB whatever the block size.
constexpr std::size_t kMaxBytesPerWrite = std::size_t{256} << 20;

// Closes an HDF5 object when it goes out of scope.
class Hid {
 public:
  Hid(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Hid() {
    if (id_ >= 0) close_(id_);
  }
  Hid(const Hid&) = delete;
  Hid& operator=(const Hid&) = delete;
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// Where this rank's rows go: its first row and the totals, from every rank's counts.
struct Placement {
  std::uint64_t first[3] = {0, 0, 0};
  std::uint64_t total[3] = {0, 0, 0};
};

Placement place(MPI_Comm comm, const MeshBlockView& block) {
  const std::uint64_t mine[3] = {block.points.size, block.tets.size, block.faces.size};
  Placement p;
  MPI_Exscan(mine, p.first, 3, MPI_UINT64_T, MPI_SUM, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) std::fill(p.first, p.first + 3, 0);  // MPI_Exscan leaves rank 0's undefined
  MPI_Allreduce(mine, p.total, 3, MPI_UINT64_T, MPI_SUM, comm);
  return p;
}

bool all_ranks(MPI_Comm comm, bool mine) {
  int here = mine ? 1 : 0, all = 0;
  MPI_Allreduce(&here, &all, 1, MPI_INT, MPI_MIN, comm);
  return all == 1;
}

// One rank's rows of a 2D dataset [total x columns]: runs of `count` rows from `data`, each
// starting at row `first`.
struct Rows {
  struct Run {
    const void* data;
    std::uint64_t count, first;
    PointIds ids = {};  // tets whose ids are not all the mesh's: written through these
  };
  const char* dataset;
  hid_t file_type;       // the dataset's values
  hid_t memory_type;     // the values in `data` (HDF5 converts them to file_type as it writes)
  std::size_t columns;   // values per row
  std::size_t row_bytes;
  std::vector<Run> runs;
  std::uint64_t total;
};

// Whether the file system holding `path` is full, for a write of `bytes`: HDF5 reports only that
// a write failed, and MPI-IO may fail a large write whole while some room is left.
bool file_system_full(const std::string& path, double bytes = 0) {
  const double free_mb = free_disk_mb(path);
  return free_mb >= 0 && free_mb < 1 + bytes / 1048576;
}

// Each collective step that ended on this rank (a write call every rank makes, an agreement), for
// the caller's watch over the write (mpi/collective_watch.hpp); none when empty.
class Steps {
 public:
  explicit Steps(const std::function<void()>& ended) : ended_(ended) {}
  void ended() const {
    if (ended_) ended_();
  }

 private:
  const std::function<void()>& ended_;
};

class Hdf5File {
 public:
  Hdf5File(MPI_Comm comm, const std::string& path, const std::string& shown, const Steps& steps)
      : comm_(comm), path_(path), shown_(shown), steps_(steps) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors become exceptions, not stderr dumps
    Hid access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    H5Pset_fapl_mpio(access.get(), comm, MPI_INFO_NULL);
    // Our own lock guards the temporary; HDF5's flock() would fail on filesystems without it.
    H5Pset_file_locking(access.get(), false, true);
    file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access.get());
    if (!all_ranks(comm, file_ >= 0)) fail("create it");
    steps_.ended();
  }
  ~Hdf5File() {
    if (file_ >= 0) H5Fclose(file_);
  }
  Hdf5File(const Hdf5File&) = delete;
  Hdf5File& operator=(const Hdf5File&) = delete;

  // Collective: creates the dataset and writes every rank's rows, in calls of bounded size.
  void write(const Rows& rows) {
    const hsize_t dims[2] = {rows.total, rows.columns};
    Hid file_space(H5Screate_simple(rows.columns == 1 ? 1 : 2, dims, nullptr), H5Sclose);
    Hid link(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
    H5Pset_create_intermediate_group(link.get(), 1);
    // No modification times: the same mesh gives the same bytes, on any number of ranks.
    Hid creation(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    H5Pset_obj_track_times(creation.get(), false);
    Hid dataset(H5Dcreate2(file_, rows.dataset, rows.file_type, file_space.get(), link.get(), creation.get(), H5P_DEFAULT),
                H5Dclose);
    if (!all_ranks(comm_, dataset.ok())) fail_open(std::string("create ") + rows.dataset, 0);
    steps_.ended();
    Hid transfer(H5Pcreate(H5P_DATASET_XFER), H5Pclose);
    H5Pset_dxpl_mpio(transfer.get(), H5FD_MPIO_COLLECTIVE);
    // Each run in calls of at most rows_per_call rows; every rank makes as many calls as the rank
    // with the most (writing nothing in its last ones).
    const std::uint64_t rows_per_call = std::max<std::uint64_t>(1, kMaxBytesPerWrite / rows.row_bytes);
    struct Call {
      const Rows::Run* run;
      std::uint64_t begin, n;
    };
    std::vector<Call> mine;
    for (const Rows::Run& run : rows.runs)
      for (std::uint64_t begin = 0; begin < run.count; begin += rows_per_call)
        mine.push_back({&run, begin, std::min(rows_per_call, run.count - begin)});
    std::uint64_t calls = mine.size();
    MPI_Allreduce(MPI_IN_PLACE, &calls, 1, MPI_UINT64_T, MPI_MAX, comm_);
    bool ok = true;
    for (std::uint64_t call = 0; call < calls; ++call) {
      const Call c = call < mine.size() ? mine[call] : Call{nullptr, 0, 0};
      ok = write_rows(dataset.get(), file_space.get(), transfer.get(), rows, c.run, c.begin, c.n) && ok;
      steps_.ended();
    }
    if (!all_ranks(comm_, ok)) fail_open(std::string("write ") + rows.dataset, double(rows.total) * double(rows.row_bytes));
  }

  void close() {
    const herr_t closed = H5Fclose(file_);
    file_ = -1;
    if (!all_ranks(comm_, closed >= 0)) fail("close it");
    steps_.ended();
  }

 private:
  bool write_rows(hid_t dataset, hid_t file_space, hid_t transfer, const Rows& rows, const Rows::Run* run,
                  std::uint64_t begin, std::uint64_t n) {
    const hsize_t start[2] = {run ? run->first + begin : 0, 0}, count[2] = {n, rows.columns};
    const hsize_t memory_dims[2] = {std::max<hsize_t>(n, 1), rows.columns};
    Hid memory_space(H5Screate_simple(rows.columns == 1 ? 1 : 2, memory_dims, nullptr), H5Sclose);
    if (n == 0) {
      H5Sselect_none(file_space);
      H5Sselect_none(memory_space.get());
    } else {
      H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, nullptr, count, nullptr);
    }
    static const char kNothing[16] = {};
    const void* data = n == 0 ? kNothing : static_cast<const char*>(run->data) + begin * rows.row_bytes;
    if (n > 0 && !run->ids.as_is()) {  // this call's rows in the mesh's ids (bounded: kMaxBytesPerWrite)
      std::vector<GlobalTet> wide(n);
      for (std::uint64_t i = 0; i < n; ++i) wide[i] = run->ids(static_cast<const Tet*>(run->data)[begin + i]);
      return H5Dwrite(dataset, H5T_NATIVE_INT64, memory_space.get(), file_space, transfer, wide.data()) >= 0;
    }
    return H5Dwrite(dataset, rows.memory_type, memory_space.get(), file_space, transfer, data) >= 0;
  }

  [[noreturn]] void fail(const std::string& step, bool full = false) {
    throw OutputError("cannot write '" + shown_ + "': parallel HDF5 could not " + step +
                      (full || file_system_full(path_) ? ": No space left on device"
                                                       : " (is the directory writable, is there space left?)"));
  }

  // Collective, with the file open on every rank. The failed file is worthless (its temporary
  // goes), but HDF5 still writes its metadata as it closes it. On a full disk that fails too, and
  // the library then keeps a half-closed file that crashes it in MPI_Finalize (h5py#914; HDF5
  // 1.10), so the file is emptied first: its own room then takes the metadata. (`bytes`: what
  // the failed step was writing.)
  [[noreturn]] void fail_open(const std::string& step, double bytes) {
    const bool full = file_system_full(path_, bytes);
    int rank = 0;
    MPI_Comm_rank(comm_, &rank);
    [[maybe_unused]] const int emptied = rank == 0 ? ::truncate(path_.c_str(), 0) : 0;  // (else closed as it is)
    MPI_Barrier(comm_);
    H5Fclose(file_);
    file_ = -1;
    fail(step, full);
  }

  MPI_Comm comm_;
  std::string path_, shown_;
  const Steps& steps_;
  hid_t file_ = -1;
};

// The values of a row in memory: points hold doubles, every other row 32-bit integers.
template <class T>
hid_t memory_type_of() {
  if constexpr (std::is_same_v<T, Point3>) {
    return H5T_NATIVE_DOUBLE;
  } else {
    static_assert(sizeof(T) % sizeof(std::int32_t) == 0 && alignof(T) == alignof(std::int32_t));
    return H5T_NATIVE_INT32;
  }
}

// A rank's rows of `values`, stored in the file as `file_type`.
template <class T>
Rows rows_of(const char* dataset, hid_t file_type, std::size_t columns, const ArrayRun<T>& values, std::uint64_t first,
             std::uint64_t total) {
  return Rows{dataset, file_type, memory_type_of<T>(), columns, sizeof(T), {{values.data, values.size, first}}, total};
}

// A rank's rows of several runs, each viewed by `values` (an ArrayRun<T>) with its first row.
template <class T, class Runs, class Values>
Rows rows_of_runs(const char* dataset, hid_t file_type, std::size_t columns, const Runs& runs, Values values,
                  std::uint64_t total) {
  Rows rows{dataset, file_type, memory_type_of<T>(), columns, sizeof(T), {}, total};
  for (const auto& run : runs) {
    const ArrayRun<T> view = values(run);
    rows.runs.push_back({view.data, view.size, run.first});
    if constexpr (std::is_same_v<T, Tet>) rows.runs.back().ids = run.ids;
  }
  return rows;
}

bool file_exists(const std::string& path) {
  struct stat info;
  return ::stat(path.c_str(), &info) == 0;
}

// Every rank learns of the worst trouble any rank has, and of which rank; then all throw.
void refuse_on_trouble(MPI_Comm comm, WriteTrouble trouble, const std::string& shown) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  int mine[2] = {static_cast<int>(trouble), rank}, worst[2] = {0, 0};
  MPI_Allreduce(mine, worst, 1, MPI_2INT, MPI_MAXLOC, comm);
  if (worst[0] == static_cast<int>(WriteTrouble::none)) return;
  const std::string who = "rank " + std::to_string(worst[1]);
  if (worst[0] == static_cast<int>(WriteTrouble::file_not_seen))
    throw OutputError("cannot write '" + shown + "': " + who +
                      " does not see the output directory rank 0 writes to; the xdmf format needs a directory all "
                      "ranks share (e.g. on a parallel or network filesystem)");
  throw OutputError("cannot write '" + shown + "': " + who + " could not take its part of the mesh");
}

}  // namespace

MeshTotals write_mesh_hdf5(MPI_Comm comm, const MeshBlockView& block, const Hdf5Paths& paths, WriteTrouble trouble,
                           const std::function<void()>& step_ended) {
  const Steps steps(step_ended);
  if (trouble == WriteTrouble::none && !(file_exists(paths.mesh) && file_exists(paths.boundary)))
    trouble = WriteTrouble::file_not_seen;
  refuse_on_trouble(comm, trouble, paths.mesh_shown);
  steps.ended();
  const Placement at = place(comm, block);
  steps.ended();
  Hdf5File mesh(comm, paths.mesh, paths.mesh_shown, steps);
  mesh.write(rows_of(hdf5_dataset::geometry, H5T_NATIVE_DOUBLE, 3, block.points, at.first[0], at.total[0]));
  mesh.write(rows_of(hdf5_dataset::topology, H5T_NATIVE_INT64, 4, block.tets, at.first[1], at.total[1]));
  mesh.write(rows_of(hdf5_dataset::region, H5T_NATIVE_INT32, 1, block.tet_region, at.first[1], at.total[1]));
  mesh.write(rows_of(hdf5_dataset::piece, H5T_NATIVE_INT32, 1, block.tet_piece, at.first[1], at.total[1]));
  mesh.close();
  Hdf5File boundary(comm, paths.boundary, paths.boundary_shown, steps);
  boundary.write(rows_of(hdf5_dataset::faces, H5T_NATIVE_INT64, 3, block.faces, at.first[2], at.total[2]));
  boundary.write(rows_of(hdf5_dataset::markers, H5T_NATIVE_INT32, 1, block.face_marker, at.first[2], at.total[2]));
  boundary.close();
  return MeshTotals{at.total[0], at.total[1], at.total[2]};
}

MeshTotals write_mesh_runs_hdf5(MPI_Comm comm, const MeshRowRuns& runs, const MeshTotals& totals,
                                const Hdf5Paths& paths, WriteTrouble trouble, const std::function<void()>& step_ended) {
  const Steps steps(step_ended);
  if (trouble == WriteTrouble::none && !(file_exists(paths.mesh) && file_exists(paths.boundary)))
    trouble = WriteTrouble::file_not_seen;
  refuse_on_trouble(comm, trouble, paths.mesh_shown);
  steps.ended();
  using TetRuns = std::vector<MeshRowRuns::Tets>;
  Hdf5File mesh(comm, paths.mesh, paths.mesh_shown, steps);
  mesh.write(rows_of_runs<Point3>(hdf5_dataset::geometry, H5T_NATIVE_DOUBLE, 3, runs.points,
                                  [](const MeshRowRuns::Points& r) { return r.points; }, totals.points));
  mesh.write(rows_of_runs<Tet>(hdf5_dataset::topology, H5T_NATIVE_INT64, 4, runs.tets,
                               [](const MeshRowRuns::Tets& r) { return r.tets; }, totals.tets));
  mesh.write(rows_of_runs<std::int32_t, TetRuns>(hdf5_dataset::region, H5T_NATIVE_INT32, 1, runs.tets,
                                                 [](const MeshRowRuns::Tets& r) { return r.region; }, totals.tets));
  mesh.write(rows_of_runs<std::int32_t, TetRuns>(hdf5_dataset::piece, H5T_NATIVE_INT32, 1, runs.tets,
                                                 [](const MeshRowRuns::Tets& r) { return r.piece; }, totals.tets));
  mesh.close();
  Hdf5File boundary(comm, paths.boundary, paths.boundary_shown, steps);
  boundary.write(rows_of(hdf5_dataset::faces, H5T_NATIVE_INT64, 3, runs.faces, runs.first_face, totals.faces));
  boundary.write(rows_of(hdf5_dataset::markers, H5T_NATIVE_INT32, 1, runs.face_marker, runs.first_face, totals.faces));
  boundary.close();
  return totals;
}

// ---------------------------------------------------------------------------------------------
// Reading: each rank its own run of rows, independently (no collective call count to agree on).

namespace {

class Hdf5Reader {
 public:
  Hdf5Reader(MPI_Comm comm, const std::string& path) : comm_(comm), path_(path) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    Hid access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    H5Pset_fapl_mpio(access.get(), comm, MPI_INFO_NULL);
    H5Pset_file_locking(access.get(), false, true);
    file_ = H5Fopen(path.c_str(), H5F_ACC_RDONLY, access.get());
    if (!all_ranks(comm, file_ >= 0)) fail("is missing or no HDF5 file");
  }
  ~Hdf5Reader() {
    if (file_ >= 0) H5Fclose(file_);
  }
  Hdf5Reader(const Hdf5Reader&) = delete;
  Hdf5Reader& operator=(const Hdf5Reader&) = delete;

  // This rank's run of the rows of a [rows x columns] dataset; rows is its total.
  template <class T>
  std::vector<T> read(const char* name, hid_t type, std::size_t columns, std::uint64_t& rows) {
    Hid dataset(H5Dopen2(file_, name, H5P_DEFAULT), H5Dclose);
    Hid space(dataset.ok() ? H5Dget_space(dataset.get()) : -1, H5Sclose);
    hsize_t dims[2] = {0, 0};
    const int rank_of_space = space.ok() ? H5Sget_simple_extent_ndims(space.get()) : -1;
    const bool shaped = rank_of_space == (columns == 1 ? 1 : 2) && H5Sget_simple_extent_dims(space.get(), dims, nullptr) >= 0 &&
                        (columns == 1 || dims[1] == columns);
    if (!all_ranks(comm_, shaped)) fail(std::string("has no dataset ") + name + " of " + std::to_string(columns) + " columns");
    rows = dims[0];
    int rank = 0, size = 1;
    MPI_Comm_rank(comm_, &rank);
    MPI_Comm_size(comm_, &size);
    const auto [first, last] = run_of(rows, rank, size);
    const std::uint64_t count = last - first;
    std::vector<T> values(count);
    bool ok = true;
    const std::uint64_t per_call = std::max<std::uint64_t>(1, kMaxBytesPerWrite / sizeof(T));
    for (std::uint64_t begin = 0; begin < count && ok; begin += per_call) {
      const std::uint64_t n = std::min(per_call, count - begin);
      const hsize_t start[2] = {first + begin, 0}, block[2] = {n, columns};
      Hid memory(H5Screate_simple(columns == 1 ? 1 : 2, block, nullptr), H5Sclose);
      H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start, nullptr, block, nullptr);
      ok = H5Dread(dataset.get(), type, memory.get(), space.get(), H5P_DEFAULT, values.data() + begin) >= 0;
    }
    if (!all_ranks(comm_, ok)) fail(std::string("cannot be read (dataset ") + name + ")");
    return values;
  }

 private:
  [[noreturn]] void fail(const std::string& what) { throw InputError("'" + path_ + "' " + what); }

  MPI_Comm comm_;
  std::string path_;
  hid_t file_ = -1;
};

}  // namespace

MeshBlock read_mesh_hdf5(MPI_Comm comm, const std::string& mesh_h5, const std::string& boundary_h5, MeshTotals& totals) {
  MeshBlock block;
  {
    Hdf5Reader mesh(comm, mesh_h5);
    block.points = mesh.read<Point3>(hdf5_dataset::geometry, H5T_NATIVE_DOUBLE, 3, totals.points);
    block.tets = mesh.read<std::array<std::int64_t, 4>>(hdf5_dataset::topology, H5T_NATIVE_INT64, 4, totals.tets);
  }
  Hdf5Reader boundary(comm, boundary_h5);
  block.faces = boundary.read<std::array<std::int64_t, 3>>(hdf5_dataset::faces, H5T_NATIVE_INT64, 3, totals.faces);
  std::uint64_t markers = 0;
  block.face_marker = boundary.read<std::int32_t>(hdf5_dataset::markers, H5T_NATIVE_INT32, 1, markers);
  if (!all_ranks(comm, markers == totals.faces))
    throw InputError("'" + boundary_h5 + "' has " + std::to_string(markers) + " markers for " +
                     std::to_string(totals.faces) + " faces");
  return block;
}

MeshTotals write_hdf5_here(const MeshOutput& output, const Hdf5Paths& paths) {
  const std::vector<std::int32_t> region = region_of_tets(output.mesh);
  MadeColumns made;
  return write_mesh_hdf5(MPI_COMM_SELF, mesh_block_view(output, region, 0, 1, made), paths);
}

}  // namespace partet
