// partet command line: mesh (MPI-aware), check, generate, refine-surface. A thin layer: it parses options,
// sets the log level, calls the library and turns errors into messages and exit codes.
#include <mpi.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "stages/check.hpp"
#include "partet/errors.hpp"
#include "stages/generate.hpp"
#include "stages/info.hpp"
#include "job/job.hpp"
#include "io/mesh_formats.hpp"
#include "common/log.hpp"
#include "mpi/driver.hpp"
#include "stages/quality.hpp"
#include "stages/refine_surface.hpp"
#include "io/read_surface.hpp"
#include "io/write_surface.hpp"
#include "io/tetgen_files.hpp"
#include "io/mesh_read.hpp"
#include "mesher/tetgen_mesher.hpp"
#include "common/version.hpp"
#include "common/memory.hpp"
#include "io/output_set.hpp"
#include "runner/interrupts.hpp"
#include "stages/quality_json.hpp"
#include "mpi/distributed_check.hpp"
#include "io/parallel_hdf5.hpp"

namespace {

// The cut planes a run's --report names. Throws InputError naming the file and the field.
std::vector<partet::CutPlane> report_cut_planes(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw partet::InputError("cannot read report '" + path + "': not a regular file");
  std::ifstream in(path);
  if (!in) throw partet::InputError("cannot open report '" + path + "'");
  const nlohmann::json report = nlohmann::json::parse(in, nullptr, false);
  if (report.is_discarded()) throw partet::InputError("report '" + path + "' is not valid JSON (a partet --report file?)");
  auto bad = [&](const std::string& field, const char* want) {
    return partet::InputError("report '" + path + "': " + field + " must be " + want);
  };
  if (!report.is_object()) throw bad("the document", "an object");
  if (!report.contains("cut_planes")) throw bad("cut_planes", "present (is this a partet --report file?)");
  const nlohmann::json& list = report["cut_planes"];
  if (!list.is_array()) throw bad("cut_planes", "a list");
  std::vector<partet::CutPlane> planes;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string at = "cut_planes[" + std::to_string(i) + "]";
    const nlohmann::json& p = list[i];
    if (!p.is_object()) throw bad(at, "an object with normal and offset");
    const nlohmann::json normal = p.value("normal", nlohmann::json());
    if (!normal.is_array() || normal.size() != 3 || !normal[0].is_number() || !normal[1].is_number() ||
        !normal[2].is_number())
      throw bad(at + ".normal", "a list of 3 numbers");
    const nlohmann::json offset = p.value("offset", nlohmann::json());
    if (!offset.is_number()) throw bad(at + ".offset", "a number");
    planes.push_back({{normal[0].get<double>(), normal[1].get<double>(), normal[2].get<double>()}, offset.get<double>()});
  }
  return planes;
}

// The quality of the seam zone and of the rest, when the run's report names the planes.
using KnownZones = std::optional<partet::ZoneQuality>;
KnownZones zone_quality(const partet::TetMesh& mesh, const std::optional<std::vector<partet::CutPlane>>& planes) {
  return planes ? KnownZones(partet::zone_quality(mesh, *planes)) : std::nullopt;
}

// The quality line and the dihedral angles' histogram.
void print_quality(const partet::MeshQuality& quality) {
  std::printf("quality: %s\n", partet::quality_line(quality).c_str());
  std::printf("dihedral angles:");
  double from = 0;
  for (std::size_t i = 0; i < partet::kDihedralBins.size(); ++i) {
    std::printf(" %g-%g: %lld%s", from, partet::kDihedralBins[i],
                static_cast<long long>(quality.dihedral_histogram[i]), i + 1 < partet::kDihedralBins.size() ? "," : "\n");
    from = partet::kDihedralBins[i];
  }
}

void print_check(const partet::CheckReport& report, const KnownZones& zones) {
  std::printf("vertices %lld, tets %lld, boundary faces %lld\n", static_cast<long long>(report.vertices),
              static_cast<long long>(report.tets), static_cast<long long>(report.boundary_faces));
  if (report.split_input_faces > 0)
    std::printf("split input triangles: %lld (tiled by boundary faces that are parts of them)\n",
                static_cast<long long>(report.split_input_faces));
  std::printf("volume: tets %.17g, surface %.17g\n", report.tet_volume, report.surface_volume);
  std::printf("euler: mesh %ld, expected %ld\n", report.euler_mesh, report.euler_expected);
  print_quality(report.quality);
  if (zones) {
    std::printf("seam zone (%lld tets): %s\n", static_cast<long long>(zones->seam.tets),
                partet::quality_line(zones->seam).c_str());
    std::printf("elsewhere (%lld tets): %s\n", static_cast<long long>(zones->elsewhere.tets),
                partet::quality_line(zones->elsewhere).c_str());
  }
  for (const auto& v : report.violations) std::printf("VIOLATION: %s\n", v.c_str());
  std::printf("%s\n", report.ok() ? "check passed" : "check FAILED");
}

void print_check_json(const partet::CheckReport& report, const KnownZones& zones) {
  nlohmann::json json = {{"ok", report.ok()},
                         {"violations", report.violations},
                         {"vertices", report.vertices},
                         {"tets", report.tets},
                         {"boundary_faces", report.boundary_faces},
                         {"split_input_faces", report.split_input_faces},
                         {"tet_volume", report.tet_volume},
                         {"surface_volume", report.surface_volume},
                         {"euler_mesh", report.euler_mesh},
                         {"euler_expected", report.euler_expected},
                         {"quality", partet::quality_json(report.quality)}};
  if (zones) {
    json["seam_zone_quality"] = partet::quality_json(zones->seam);
    json["elsewhere_quality"] = partet::quality_json(zones->elsewhere);
  }
  std::printf("%s\n", json.dump(2).c_str());
}

// Exit code 0 when the check passes, 1 when it fails (2 is kept for usage errors).
// A publish a killed run left half done at this prefix is completed before the files are read.
void settle(const std::string& prefix) {
  if (const std::string done = partet::settle_publish(prefix); !done.empty()) partet::log::warning(done);
}

// Whether PATH's extension names `format`; `run` (if given) is then PATH without it.
bool names_format(const std::string& path, partet::MeshFormat format, std::string* run = nullptr) {
  partet::MeshFormat named;
  std::string without;
  if (!partet::split_format_extension(path, named, without) || named != format) return false;
  if (run) *run = without;
  return true;
}

// An MSH file PATH's run (PATH without .msh) may have been published at RUN or, for a partition
// file PREFIX_i.msh, at PREFIX.
void settle_msh(const std::string& path, const std::string& run) {
  settle(run);
  if (std::string parts; partet::partition_file_prefix(path, parts)) settle(parts);
}

// A set named by one of its files (an MSH, VTK or MEDIT file): its run may have been published
// at PATH without its extension, or (an MSH partition file) at the set's prefix.
void settle_named(const std::string& path) {
  partet::MeshFormat format;
  std::string run;
  partet::split_format_extension(path, format, run);
  format == partet::MeshFormat::msh ? settle_msh(path, run) : settle(run);
}

// The set to check: TetGen files at a prefix, or a set named by one of its files (mesh_read.hpp).
partet::TetgenFileSet read_set_to_check(const std::string& prefix) {
  if (!partet::reads_mesh_file(prefix)) {
    settle(prefix);
    return partet::read_tetgen_set(prefix);
  }
  settle_named(prefix);
  return partet::read_mesh_set(prefix);
}

int run_check(const std::string& input_path, const std::string& prefix, const std::string& report_path, bool json,
              partet::BoundaryRule rule) {
  std::optional<std::vector<partet::CutPlane>> planes;  // read first: a bad report fails before the work
  if (!report_path.empty()) planes = report_cut_planes(report_path);
  const partet::TetgenFileSet files = read_set_to_check(prefix);
  const partet::CheckReport report = partet::check_mesh_files(partet::read_surface(input_path), files, rule);
  const KnownZones zones = zone_quality(files.mesh, planes);
  json ? print_check_json(report, zones) : print_check(report, zones);
  return report.ok() ? 0 : 1;
}

// The check on every rank of the job, each its part: an XDMF set (alone: on one rank), or under a
// launcher TetGen files or a set named by one of its files (MSH, VTK, MEDIT). Rank 0 prints.
partet::DistributedCheckReport check_on_ranks(const std::string& input_path, const std::string& path) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  std::string run;
  if (names_format(path, partet::MeshFormat::xdmf, &run)) {
    if (rank == 0) settle(run);
    MPI_Barrier(MPI_COMM_WORLD);
    return partet::check_xdmf_set(MPI_COMM_WORLD, input_path, run);
  }
  const bool named = partet::reads_mesh_file(path);
  if (rank == 0) named ? settle_named(path) : settle(path);
  MPI_Barrier(MPI_COMM_WORLD);
  return named ? partet::check_mesh_file_set(MPI_COMM_WORLD, input_path, path)
               : partet::check_tetgen_set(MPI_COMM_WORLD, input_path, path);
}

int run_check_distributed(const std::string& input_path, const std::string& path, bool json) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const partet::DistributedCheckReport report = check_on_ranks(input_path, path);
  if (rank != 0) return report.ok() ? 0 : 1;
  if (json) {
    std::printf("%s\n", nlohmann::json{{"ok", report.ok()},
                                       {"violations", report.violations},
                                       {"vertices", report.vertices},
                                       {"tets", report.tets},
                                       {"boundary_faces", report.boundary_faces},
                                       {"tet_volume", report.tet_volume},
                                       {"surface_volume", report.surface_volume},
                                       {"euler_mesh", report.euler_mesh},
                                       {"euler_expected", report.euler_expected},
                                       {"quality", partet::quality_json(report.quality)}}
                                .dump(2)
                                .c_str());
  } else {
    int ranks = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    std::printf("%lld vertices, %lld tets, %lld boundary faces (checked on %d rank%s)\n",
                static_cast<long long>(report.vertices), static_cast<long long>(report.tets),
                static_cast<long long>(report.boundary_faces), ranks, ranks == 1 ? "" : "s");
    std::printf("volume %.17g (input encloses %.17g), V-E+F-T %ld (expected %ld)\n", report.tet_volume,
                report.surface_volume, report.euler_mesh, report.euler_expected);
    print_quality(report.quality);
    for (const auto& v : report.violations) std::printf("VIOLATION: %s\n", v.c_str());
    std::printf("%s\n", report.ok() ? "check passed" : "check FAILED");
  }
  return report.ok() ? 0 : 1;
}

// This process's rank when an MPI launcher started it (before MPI_Init: from its environment).
int launched_rank() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK", "SLURM_PROCID"})
    if (const char* value = std::getenv(name)) return std::atoi(value);
  return 0;
}

// How many ranks an MPI launcher started (before MPI_Init: from its environment); 1 without one.
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
  bool launched = false;  // srun sets SLURM_PROCID in a batch script too: such runs keep the defaults
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK", "SLURM_PROCID"})
    launched = launched || std::getenv(name);
  if (!launched) {
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

// Whether MPI can make its session directory under dir: the nearest existing ancestor (it makes
// the missing ones) must be a directory this process may write.
bool session_directory_possible(std::filesystem::path dir) {
  std::error_code error;
  while (!std::filesystem::exists(dir, error) && dir.has_relative_path()) dir = dir.parent_path();
  return std::filesystem::is_directory(dir, error) && ::access(dir.c_str(), W_OK | X_OK) == 0;
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

// partet check INPUT PREFIX.xdmf (or any set under a launcher): under MPI, each rank checking its
// part (see check_on_ranks).
int run_check_on_ranks(int argc, char** argv, const std::string& input, const std::string& path, bool json) {
  if (const std::string problem = unwritable_session_directory(); !problem.empty()) {
    partet::log::error(problem);
    return 2;
  }
  start_mpi(argc, argv);
  int code = 1;
  try {
    code = run_check_distributed(input, path, json);
  } catch (const partet::InputError& e) {
    // Every rank throws it (the ranks agree on a file that cannot be read): the first says why.
    if (launched_rank() == 0) partet::log::error(e.what());
  } catch (const std::exception& e) {
    // This rank alone (out of memory in a check step, say): the others wait for it in the
    // check's exchanges, so the job must end here, or it would wait forever.
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    partet::log::error(dynamic_cast<const std::bad_alloc*>(&e)
                           ? "out of memory on rank " + std::to_string(rank) +
                                 ": run the check on more ranks (mpirun -n N partet check ...)"
                           : std::string(e.what()) + " (on rank " + std::to_string(rank) + ")");
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  MPI_Finalize();
  return code;
}

int run_mesh(int argc, char** argv, const partet::MeshJob& job) {
  if (const std::string problem = unwritable_session_directory(); !problem.empty()) {
    partet::log::error(problem);
    return 2;
  }
  start_mpi(argc, argv);
  int code = 1, ranks = 1;
  partet::RunFigures status_figures;
  try {
    const partet::mpi::JobStatus status = partet::mpi::run_mesh_job(job);
    code = status.exit_code;
    status_figures = status.figures;
    ranks = status.ranks;
    if (!status.error.empty()) {
      // The library's messages name no flags; what the user can change is said here.
      const bool advise = status.meshing_failed && job.options.pieces > 1 && !status.out_of_time;
      const bool split = status.split_faces_may_help && !job.options.allow_split_faces;
      const std::string error =
          status.error + (advise ? "; try another --pieces value or --axis" : "") +
          (status.out_of_time ? "; --piece-timeout gives each piece more CPU time" : "") +
          (split ? " (--allow-split-faces accepts a mesh that splits some input triangles, as tetgen -p without -Y "
                   "gives)"
                 : "");
      // The run has failed and says so here: an interrupt now (mpirun ending this rank because
      // another one exited first) says this error, once, instead of its own message.
      partet::interrupts::set_messages("error: " + error, "error: " + error);
      partet::log::error(error);
      partet::interrupts::set_messages("", "");
    }
  } catch (const std::exception& e) {
    partet::log::error(e.what());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  MPI_Finalize();
  // After MPI_Finalize: the other ranks have exited and leave the cores to TetGen.
  if (code == 0 && job.compare_tetgen && launched_rank() == 0) {
    try {
      partet::print_comparison(status_figures, partet::tetgen_alone(job), ranks, job.options.pieces);
    } catch (const std::exception& e) {
      partet::log::error(std::string("--compare-tetgen: ") + e.what());
    }
  }
  return code;
}

// What the command line asked for.
struct CommandLine {
  partet::MeshJob job;
  std::string quality, axis = "auto", balance = "cost";
  std::vector<std::string> formats;
  bool quiet = false, verbose = false, heal = false, no_heal = false, no_polish = false;
  std::string check_input, check_prefix, check_report;
  bool check_json = false, check_split = false;
  std::string shape, generate_output;
  partet::ThinWallPart thin_walls;
  std::string info_file;
  bool info_json = false;
  int faces = 2000;
  std::string refine_input, refine_output;
  int loop_steps = 1;
};

// Numbers must be finite: "nan" passes a range check (every comparison with it is false).
const CLI::Validator kFinite(
    [](std::string& text) {
      double value = 0;
      try {
        value = std::stod(text);
      } catch (const std::exception&) {
        return std::string();  // not a number: the range check says so
      }
      return std::isfinite(value) ? std::string() : "the value must be a finite number, not " + text;
    },
    "FINITE");

const CLI::Validator kWritableDirectory(
    [](std::string& path) {
      std::error_code ec;
      if (!std::filesystem::is_directory(path, ec)) return "directory '" + path + "' does not exist";
      if (::access(path.c_str(), W_OK | X_OK) != 0) return "directory '" + path + "' is not writable";
      return std::string();
    },
    "DIR");

CLI::App* add_mesh_command(CLI::App& app, CommandLine& c) {
  auto* mesh = app.add_subcommand("mesh", "tetrahedralize a closed surface (run under mpirun for several ranks)");
  auto& job = c.job;
  mesh->add_option("input", job.input, "closed triangle surface (.off .obj .ply .stl)")->required();
  mesh->add_option("-o,--output", job.output_prefix,
                   "output prefix (PREFIX.node .ele .face .neigh); an extension .vtu .pvtu .msh .mesh .xdmf "
                   ".node chooses the format")
      ->required();
  mesh->add_option("--format", c.formats,
                   "formats to write, comma-separated: tetgen (default), vtu, pvtu (one .vtu per piece), msh "
                   "(Gmsh 4.1), msh-binary, msh-parts (PREFIX_1.msh ...: one Gmsh 4.1 file per partition, as gmsh "
                   "splits them), msh-parts-binary, medit (.mesh), xdmf (XDMF + one HDF5 file all ranks write at "
                   "once)")
      ->delimiter(',')
      ->check(CLI::IsMember(partet::mesh_format_names()));
  mesh->add_option("-k,--pieces", job.options.pieces, "number of pieces (cut planes + 1)")
      ->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  mesh->add_option("-d,--density", job.options.density,
                   "cap refinement: target cap edge length = mean cut-loop edge length / D; 0 = no interior cap "
                   "points, so without --quality no vertex is left on a cut (costs little on most models, up to "
                   "5x on smooth subdivided ones)")
      ->check(kFinite)
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  mesh->add_option("-q,--quality", c.quality, "TetGen quality refinement R[/ANGLE] (-q); boundary stays untouched");
  mesh->add_option("--balance", c.balance,
                   "what the cut planes balance: cost (each piece's estimated TetGen cost: its triangles, "
                   "caps included) or vertices (input vertex counts)")
      ->check(CLI::IsMember({"cost", "vertices"}))
      ->capture_default_str();
  mesh->add_option(
          "--axis", c.axis,
          "cut direction: auto = coordinate axis nearest the PCA axis (exactly planar caps), pca = the PCA axis, "
          "x, y or z = that coordinate axis; when the cuts keep failing, the other directions are tried too")
      ->check(CLI::IsMember({"auto", "pca", "x", "y", "z"}))
      ->capture_default_str();
  mesh->add_option("--piece-timeout", job.options.run.timeout_seconds,
                   "CPU seconds before meshing one piece is given up (0: scaled with the piece's size); time "
                   "waiting for a core does not count, up to 4 times this in wall time; a rank that does not "
                   "answer by then ends the job")
      ->check(kFinite)
      ->check(CLI::Range(0.0, 1e7))
      ->capture_default_str();
  mesh->add_option("--max-attempts", job.options.max_attempts,
                   "partitions tried at most before giving up (the retries try other cut planes, other directions, "
                   "fewer pieces, then the whole input as one piece)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  mesh->add_option("--checkpoint", job.options.run.checkpoint,
                   "keep every meshed piece in DIR (made if missing): a rerun of the same job with the same DIR takes "
                   "the pieces found there instead of meshing them again, so a run stopped by a time limit, a "
                   "preemption, a crash or Ctrl-C loses none of the pieces it had meshed; same output")
      ->type_name("DIR");
  mesh->add_option("--scratch", job.options.scratch,
                   "the paper's memory mode: each piece's mesh, but for the tets around the cuts, waits in a file "
                   "in DIR (on the node of the rank holding it) until the output is assembled, instead of in memory")
      ->type_name("DIR");
  auto* heal = mesh->add_flag(
      "--heal", c.heal, "remove the caps' interior points too, re-meshing around every cut (default with --quality)");
  mesh->add_flag(
          "--no-heal", c.no_heal,
          "keep the caps' interior points, remove only the cut vertices on input edges (default without --quality)")
      ->excludes(heal);
  mesh->add_flag("--no-polish", c.no_polish,
                 "with --quality, do not re-mesh the neighbourhoods of the poorest tets (dihedral angle < 5 deg or "
                 "AMIPS > 30) after healing");
  mesh->add_option("--report", job.report_path,
                   "write a JSON report: stage times and memory, per-rank and per-piece figures, counts, retries, "
                   "cut planes (with --check also the quality, overall and at the seams)");
  mesh->add_flag("--allow-split-faces", job.options.allow_split_faces,
                 "when TetGen cannot mesh the input without putting points on its surface, accept a mesh (of the "
                 "whole input as one piece, as tetgen -p without -Y) that splits some input triangles, instead of "
                 "failing; their parts get boundary marker 2");
  mesh->add_flag("--check", job.check_output, "verify the result (as `partet check`) before writing it");
  mesh->add_flag("--compare-tetgen", job.compare_tetgen,
                 "afterwards, mesh the whole input with TetGen alone (same switches, if it fits in memory) and "
                 "print both runs' time, memory, tets and quality side by side");
  mesh->add_flag("--quiet", c.quiet, "print errors only");
  mesh->add_flag("--verbose", c.verbose, "print more detail");
  mesh->add_option("--dump-pieces", job.dump_pieces_dir,
                   "write each piece's closed surface to DIR/piece_<i>.off (debugging)")
      ->check(kWritableDirectory);
  return mesh;
}

CLI::App* add_check_command(CLI::App& app, CommandLine& c) {
  auto* check = app.add_subcommand("check", "verify a tet mesh against its input surface and print its quality");
  check->add_option("input", c.check_input, "the surface that was meshed")->required();
  check->add_option("prefix", c.check_prefix,
                    "prefix of the .node/.ele files; PREFIX.msh, or one file of an MSH partition set "
                    "(PREFIX_1.msh: the whole set is read); PREFIX.vtu, PREFIX.pvtu (the set), PREFIX.mesh "
                    "(MEDIT); or PREFIX.xdmf, the XDMF set. Under mpirun every rank reads and checks its part of any "
                    "of them, so a mesh too large for one process can be checked")
      ->required();
  check->add_flag("--json", c.check_json, "print the result as JSON");
  check->add_flag("--allow-split-faces", c.check_split,
                  "accept boundary faces that are parts of input triangles, tiling them (a mesh made with mesh "
                  "--allow-split-faces)");
  check->add_option("--report", c.check_report,
                    "the --report of the run that made the mesh: also give the quality of the seam zone (tets "
                    "crossing a cut plane) and of the rest");
  return check;
}

CLI::App* add_generate_command(CLI::App& app, CommandLine& c) {
  auto* generate = app.add_subcommand("generate", "write a generated closed test surface");
  const auto listed = [](const std::vector<std::string>& names) {
    std::string text;
    for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
    return text;
  };
  generate->add_option("shape", c.shape,
                       listed(partet::generated_shape_names()) + "; or a CAD-like part with thin walls: " +
                           listed(partet::thin_wall_kinds()))
      ->required();
  generate->add_option("--walls", c.thin_walls.walls, "thin-wall parts: number of walls")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  generate->add_option("--wall", c.thin_walls.wall, "thin-wall parts: thickness of a wall")
      ->check(kFinite)
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  generate->add_option("--gap", c.thin_walls.gap, "thin-wall parts: space between walls")
      ->check(kFinite)
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  generate->add_option("--turn", c.thin_walls.turn_degrees,
                       "thin-wall parts: degrees turned about the extrusion axis (0: axis aligned, as CAD parts are)")
      ->check(kFinite)
      ->capture_default_str();
  generate->add_option("--faces", c.faces, "about this many triangles")
      ->check(CLI::Range(1, 1 << 28))
      ->capture_default_str();
  generate->add_option("-o,--output", c.generate_output, "output .off file")->required();
  return generate;
}

CLI::App* add_info_command(CLI::App& app, CommandLine& c) {
  auto* info = app.add_subcommand("info",
                                  "describe a surface (counts, bounds, shells, genus, closed/manifold/oriented, "
                                  "self-intersections) or a tet mesh (counts, volume, solids, quality)");
  info->add_option("file", c.info_file,
                   "a surface (.off .obj .ply .stl), TetGen files (PREFIX, PREFIX.node or PREFIX.ele) or a tet "
                   "mesh in another format partet writes (.vtu, .pvtu, .msh or a partition file, .mesh, .xdmf)")
      ->required();
  info->add_flag("--json", c.info_json, "print the description as JSON");
  return info;
}

std::string bounds_text(const partet::Bounds& b) {
  char text[200];
  std::snprintf(text, sizeof text, "[%.6g, %.6g] x [%.6g, %.6g] x [%.6g, %.6g]", b.min[0], b.max[0], b.min[1],
                b.max[1], b.min[2], b.max[2]);
  return text;
}

nlohmann::json bounds_json(const partet::Bounds& b) { return {{"min", b.min}, {"max", b.max}}; }

int print_surface_info(const std::string& path, bool json) {
  const partet::SurfaceInfo i = partet::surface_info(partet::read_surface(path));
  const char* yes[] = {"no", "yes"};
  if (json) {
    std::printf("%s\n", nlohmann::json{{"kind", "surface"}, {"vertices", i.vertices}, {"unused_vertices", i.unused_vertices},
                                       {"faces", i.faces}, {"edges", i.edges}, {"bounds", bounds_json(i.bounds)},
                                       {"shells", i.shells}, {"euler", i.euler}, {"genus", i.genus},
                                       {"border_edges", i.border_edges}, {"non_manifold_edges", i.non_manifold_edges},
                                       {"misoriented_edges", i.misoriented_edges},
                                       {"volume", static_cast<double>(i.volume)},
                                       {"self_intersection", i.self_intersection},
                                       {"meshable", i.meshable()}}.dump(2).c_str());
    return 0;
  }
  std::printf("surface %s: %lld vertices (%lld unused), %lld faces, %lld edges\n", path.c_str(),
              static_cast<long long>(i.vertices), static_cast<long long>(i.unused_vertices),
              static_cast<long long>(i.faces), static_cast<long long>(i.edges));
  std::printf("bounds: %s\n", bounds_text(i.bounds).c_str());
  std::printf("shells %lld, Euler characteristic %lld, genus %s\n", static_cast<long long>(i.shells),
              static_cast<long long>(i.euler), i.genus < 0 ? "unknown (not closed, manifold and oriented)"
                                                            : std::to_string(i.genus).c_str());
  std::printf("closed %s (%lld border edges), manifold %s (%lld edges in 3+ faces), oriented %s (%lld edges)\n",
              yes[i.closed()], static_cast<long long>(i.border_edges), yes[i.manifold()],
              static_cast<long long>(i.non_manifold_edges), yes[i.oriented()],
              static_cast<long long>(i.misoriented_edges));
  if (i.closed() && i.oriented())
    std::printf("enclosed volume %.9Lg (%s)\n", i.volume, i.volume > 0 ? "outward" : "inside out");
  std::printf("self-intersections: %s\n", !i.self_intersection_checked ? "not checked (needs a closed, oriented surface)"
                                           : i.self_intersection.empty() ? "none"
                                                                         : i.self_intersection.c_str());
  std::printf("meshable by partet: %s\n", yes[i.meshable()]);
  return 0;
}

// A TetGen file set when FILE is PREFIX.node, PREFIX.ele or a PREFIX with PREFIX.node beside it.
bool tet_mesh_prefix(const std::string& file, std::string& prefix) {
  for (const char* ext : {".node", ".ele"}) {
    const std::string e = ext;
    if (file.size() > e.size() && file.compare(file.size() - e.size(), e.size(), e) == 0) {
      prefix = file.substr(0, file.size() - e.size());
      return true;
    }
  }
  prefix = file;
  std::error_code ec;
  return std::filesystem::exists(file + ".node", ec);  // not opened here: a FIFO would block
}

// An XDMF set's tets, read in this process (parallel HDF5 needs MPI, on one rank here).
partet::TetMesh read_xdmf_here(int argc, char** argv, const std::string& run) {
  if (const std::string problem = unwritable_session_directory(); !problem.empty()) throw partet::Error(problem);
  start_mpi(argc, argv);
  partet::MeshTotals totals;
  partet::MeshBlock block;
  try {
    block = partet::read_mesh_hdf5(MPI_COMM_SELF, run + ".h5", run + "_boundary.h5", totals);
  } catch (...) {
    MPI_Finalize();
    throw;
  }
  MPI_Finalize();
  if (block.points.size() > static_cast<std::size_t>(INT32_MAX) || block.tets.size() > static_cast<std::size_t>(INT32_MAX))
    throw partet::InputError("'" + run + ".h5' holds more than 2^31 points or tets, more than one process can "
                             "describe: check it on several ranks instead (mpirun -n N partet check INPUT " +
                             run + ".xdmf)");
  partet::TetMesh mesh;
  mesh.points = std::move(block.points);
  mesh.tets.reserve(block.tets.size());
  for (const auto& t : block.tets) {
    partet::Tet tet;
    for (int j = 0; j < 4; ++j) {
      if (t[j] < 0 || t[j] >= static_cast<std::int64_t>(mesh.points.size()))
        throw partet::InputError("'" + run + ".h5' has a tet with point " + std::to_string(t[j]) + " of " +
                                 std::to_string(mesh.points.size()));
      tet[j] = static_cast<std::int32_t>(t[j]);
    }
    mesh.tets.push_back(tet);
  }
  return mesh;
}

// The tets FILE names, its publish settled first: TetGen files at PREFIX, a file of another format
// partet writes (its set: a .pvtu index, MSH partitions), or an XDMF set.
partet::TetMesh read_tet_mesh_to_describe(int argc, char** argv, const std::string& file, const std::string& prefix) {
  std::string run;
  if (names_format(file, partet::MeshFormat::xdmf, &run)) {
    settle(run);
    return read_xdmf_here(argc, argv, run);
  }
  if (partet::reads_mesh_file(file)) {
    settle_named(file);
    return std::move(partet::read_mesh_set(file).mesh);
  }
  settle(prefix);
  return partet::read_tetgen_files(prefix);
}

int print_tet_mesh_info(const partet::TetMesh& mesh, const std::string& prefix, bool json) {
  const partet::TetMeshInfo i = partet::tet_mesh_info(mesh);
  if (json) {
    std::printf("%s\n", nlohmann::json{{"kind", "tet mesh"}, {"vertices", i.vertices}, {"tets", i.tets},
                                       {"boundary_faces", i.boundary_faces}, {"solids", i.solids},
                                       {"bounds", bounds_json(i.bounds)}, {"volume", static_cast<double>(i.volume)},
                                       {"inverted_tets", i.inverted_tets},
                                       {"quality", partet::quality_json(i.quality)}}.dump(2).c_str());
    return 0;
  }
  std::printf("tet mesh %s: %lld vertices, %lld tets, %lld boundary faces, %lld solid%s\n", prefix.c_str(),
              static_cast<long long>(i.vertices), static_cast<long long>(i.tets),
              static_cast<long long>(i.boundary_faces), static_cast<long long>(i.solids), i.solids == 1 ? "" : "s");
  std::printf("bounds: %s\n", bounds_text(i.bounds).c_str());
  std::printf("volume %.9Lg (%lld inverted or flat tets)\n", i.volume, static_cast<long long>(i.inverted_tets));
  std::printf("quality: %s\n", partet::quality_line(i.quality).c_str());
  return 0;
}

int run_info(int argc, char** argv, const CommandLine& c) {
  std::string prefix;
  const bool tetgen = tet_mesh_prefix(c.info_file, prefix);
  if (!tetgen && !partet::reads_mesh_file(c.info_file) && !names_format(c.info_file, partet::MeshFormat::xdmf))
    return print_surface_info(c.info_file, c.info_json);
  const std::string shown = tetgen ? prefix : c.info_file;
  return print_tet_mesh_info(read_tet_mesh_to_describe(argc, argv, c.info_file, prefix), shown, c.info_json);
}

CLI::App* add_refine_command(CLI::App& app, CommandLine& c) {
  auto* refine = app.add_subcommand("refine-surface",
                                    "Loop-subdivide a closed surface (each step: 4x the faces), e.g. to make a large "
                                    "benchmark input from a shared model");
  refine->add_option("input", c.refine_input, "closed triangle surface (.off .obj .ply .stl)")->required();
  refine->add_option("-o,--output", c.refine_output, "output .off file")->required();
  refine->add_option("--loop", c.loop_steps, "number of Loop subdivision steps")
      ->check(CLI::Range(0, 8))
      ->capture_default_str();
  return refine;
}

// --format, plus the format -o's extension names (unless --format already writes that file).
// Throws OptionError when two formats would write the same file.
void choose_formats(const std::vector<std::string>& names, partet::MeshJob& job) {
  job.formats.clear();
  for (const std::string& name : names) {
    const partet::MeshFormat f = partet::mesh_format(name);
    if (std::find(job.formats.begin(), job.formats.end(), f) != job.formats.end()) continue;
    for (partet::MeshFormat other : job.formats)
      if (partet::format_paths(other, "P").front() == partet::format_paths(f, "P").front())
        throw partet::OptionError("--format: " + partet::mesh_format_name(other) + " and " + name +
                                  " both write PREFIX" + partet::format_paths(f, "").front() + "; choose one");
    job.formats.push_back(f);
  }
  partet::MeshFormat from_extension;
  std::string prefix;
  if (partet::split_format_extension(job.output_prefix, from_extension, prefix)) {
    job.output_prefix = prefix;
    const std::string path = partet::format_paths(from_extension, prefix).front();
    bool written = false;
    for (partet::MeshFormat f : job.formats) written = written || partet::format_paths(f, prefix).front() == path;
    if (!written) job.formats.insert(job.formats.begin(), from_extension);
  }
  if (job.formats.empty()) job.formats.push_back(partet::MeshFormat::tetgen);
}

// Writes an OFF file all or nothing, as the mesh files are.
void publish_off(const partet::SurfaceMesh& s, const std::string& path) {
  partet::OutputSet set(partet::journal_path(path));
  set.add(path, [&](const std::string& temporary) { partet::write_off(s, temporary); });
  partet::interrupts::set_messages("interrupted (%s): " + path + " is as it was", "");
  set.publish();
}

int run_refine(const CommandLine& c) {
  partet::check_output_paths({c.refine_output}, {c.refine_input});
  const partet::SurfaceMesh s = partet::loop_subdivide(partet::read_surface(c.refine_input), c.loop_steps);
  publish_off(s, c.refine_output);
  std::printf("wrote %s: %zu vertices, %zu faces\n", c.refine_output.c_str(), s.points.size(), s.triangles.size());
  return 0;
}

int run_generate(const CommandLine& c) {
  partet::check_output_paths({c.generate_output}, {});
  const std::vector<std::string> kinds = partet::thin_wall_kinds();
  partet::ThinWallPart part = c.thin_walls;
  part.kind = c.shape;
  const partet::SurfaceMesh s = std::find(kinds.begin(), kinds.end(), c.shape) != kinds.end()
                                    ? partet::generate_thin_walls(part)
                                    : partet::generate_surface(c.shape, c.faces);
  publish_off(s, c.generate_output);
  std::printf("wrote %s: %zu vertices, %zu faces\n", c.generate_output.c_str(), s.points.size(), s.triangles.size());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // Before anything else, and before MPI starts its threads: signals end a run cleanly.
  partet::interrupts::install();
  partet::return_large_frees_to_system();
  CLI::App app{"partet: distributed boundary-preserving tetrahedral meshing around TetGen"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("partet ") + PARTET_VERSION + " (TetGen 1.5, CGAL " +
                                        partet::cgal_version() + ", " + partet::mpi::library_version() + ")");
  CommandLine c;
  add_mesh_command(app, c);
  auto* check = add_check_command(app, c);
  auto* generate = add_generate_command(app, c);
  auto* refine = add_refine_command(app, c);
  auto* info = add_info_command(app, c);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    // Usage errors: one line, exit code 2, from the first rank only when launched by MPI.
    return usage_error(argc, argv, std::string(e.what()) + " (see partet --help)");
  }

  try {
    // An XDMF set is always checked on the job's ranks (alone: one), each its part; under a
    // launcher with several ranks every set is (one process reads it whole, and also reports the
    // quality).
    const bool xdmf = names_format(c.check_prefix, partet::MeshFormat::xdmf);
    if (*check && (xdmf || launched_size() > 1)) {
      if (c.check_split || !c.check_report.empty())
        return usage_error(argc, argv,
                           std::string("--allow-split-faces and --report ") +
                               (xdmf ? "apply to TetGen files; check those (PREFIX) instead of PREFIX.xdmf"
                                     : "need the whole mesh in one process: run partet check without mpirun"));
      return run_check_on_ranks(argc, argv, c.check_input, c.check_prefix, c.check_json);
    }
    if (*check)
      return run_check(c.check_input, c.check_prefix, c.check_report, c.check_json,
                       c.check_split ? partet::BoundaryRule::split_allowed : partet::BoundaryRule::exact);
    if (*generate) return run_generate(c);
    if (*refine) return run_refine(c);
    if (*info) return run_info(argc, argv, c);
  } catch (const partet::OptionError& e) {
    partet::log::error(e.what());
    return 2;  // what the command line asks for cannot be done
  } catch (const std::bad_alloc&) {
    partet::log::error("out of memory: the input is too large for this machine's memory");
    return 1;
  } catch (const std::exception& e) {
    partet::log::error(e.what());
    return 1;
  }
  try {
    c.job.options.tetgen.quality = partet::parse_quality(c.quality);
  } catch (const partet::OptionError& e) {
    return usage_error(argc, argv, std::string("--quality: ") + e.what());
  }
  try {
    choose_formats(c.formats, c.job);
  } catch (const partet::OptionError& e) {
    return usage_error(argc, argv, e.what());
  }
  c.job.options.heal = c.heal ? partet::Heal::on : c.no_heal ? partet::Heal::off : partet::Heal::automatic;
  c.job.options.polish = !c.no_polish;
  c.job.options.balance = c.balance == "vertices" ? partet::Balance::vertices : partet::Balance::cost;
  c.job.options.axis = c.axis == "pca" ? partet::CutAxis::pca
                       : c.axis == "x" ? partet::CutAxis::x
                       : c.axis == "y" ? partet::CutAxis::y
                       : c.axis == "z" ? partet::CutAxis::z
                                       : partet::CutAxis::coordinate_near_pca;
  partet::log::set_level(c.quiet     ? partet::log::Level::quiet
                         : c.verbose ? partet::log::Level::verbose
                                     : partet::log::Level::normal);
  return run_mesh(argc, argv, c.job);
}
