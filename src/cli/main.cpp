// partet command line: mesh (MPI-aware), check, info, generate, refine-surface. A thin layer: it
// parses options, sets the log level, calls the library and turns errors into messages and exit
// codes. The check and info commands, and how MPI is started, have files of their own beside it.
#include <mpi.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "cli/check_command.hpp"
#include "cli/info_command.hpp"
#include "cli/launch.hpp"
#include "cli/published_sets.hpp"
#include "common/log.hpp"
#include "common/memory.hpp"
#include "common/version.hpp"
#include "io/mesh_formats.hpp"
#include "io/output_set.hpp"
#include "io/read_surface.hpp"
#include "io/write_surface.hpp"
#include "job/compare_tetgen.hpp"
#include "job/job.hpp"
#include "mesher/tetgen_mesher.hpp"
#include "mpi/driver.hpp"
#include "runner/interrupts.hpp"
#include "stages/generate.hpp"
#include "stages/refine_surface.hpp"

namespace {

using partet::cli::launched_rank;
using partet::cli::launched_size;
using partet::cli::names_format;
using partet::cli::start_mpi;
using partet::cli::unwritable_session_directory;
using partet::cli::usage_error;
using partet::cli::run_check;
using partet::cli::run_check_on_ranks;
using partet::cli::run_info;

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
  mesh->add_option("--wait-for-space", job.wait_for_space_minutes,
                   "minutes to wait, once the mesh is made, for room on the output's filesystem when it has less "
                   "than the files need at least (a neighbouring job filled it) or fills up during the write, "
                   "instead of losing the mesh; a filesystem already that full is refused before the meshing")
      ->check(kFinite)
      ->check(CLI::Range(0.0, 40.0))
      ->capture_default_str();
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
    if (*info) return run_info(argc, argv, c.info_file, c.info_json);
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
