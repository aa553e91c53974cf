// Writers for the formats users open the mesh in: VTK XML (.vtu/.pvtu), MEDIT; Gmsh MSH 4.1 is in
// msh.cpp.
// Each is checked in the tests by an independent reader (meshio, gmsh).
#include "io/mesh_formats.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "common/group_items.hpp"
#include "common/parallel.hpp"
#include "common/paths.hpp"
#include "io/buffered_file.hpp"
#include "io/msh.hpp"
#include "io/row_lines.hpp"
#include "io/tetgen_files.hpp"
#include "io/vtu_file.hpp"
#include "io/xdmf.hpp"
#include "io/xml_text.hpp"
#include "partet/errors.hpp"
#include "stages/info.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

// ---------------------------------------------------------------------------------------------
// Shared

std::int32_t piece_of(const TetMesh& mesh, std::size_t t) { return mesh.piece.empty() ? -1 : mesh.piece[t]; }

// ---------------------------------------------------------------------------------------------
// VTK XML

void add_cell(const MeshOutput& output, const std::vector<std::int32_t>& region, std::size_t t, VtuCells& cells) {
  cells.offsets.push_back(static_cast<std::int64_t>(cells.connectivity.size()));
  cells.types.push_back(10);  // VTK_TETRA
  cells.piece.push_back(piece_of(output.mesh, t));
  cells.region.push_back(region[t]);
}

// The tets of each piece value, for a .pvtu set's files: one pass over the tets for all of them
// (not one per piece), and one renumbering array for all of them, reset after each piece.
class PieceCells {
 public:
  PieceCells(const MeshOutput& output, const std::vector<std::int32_t>& region)
      : output_(output), region_(region), new_id_(output.mesh.points.size(), -1) {
    // Tets in piece order (the seams' -1 first), by a counting sort.
    const std::vector<std::int32_t>& piece = output.mesh.piece;
    lowest_ = piece.empty() ? -1 : *std::min_element(piece.begin(), piece.end());
    const int highest = piece.empty() ? -1 : *std::max_element(piece.begin(), piece.end());
    group_items(
        output.mesh.tets.size(), static_cast<std::size_t>(highest - lowest_) + 1,
        [&](std::size_t t) { return slot(t); }, order_, start_);
  }

  // The tets with this piece value, their points renumbered from 0 in order of first use.
  VtuCells of(int piece) {
    const TetMesh& mesh = output_.mesh;
    VtuCells cells;
    if (piece < lowest_ || static_cast<std::size_t>(piece - lowest_) + 1 >= start_.size()) return cells;
    const auto s = static_cast<std::size_t>(piece - lowest_);
    std::int64_t next = 0;
    for (std::size_t i = start_[s]; i < start_[s + 1]; ++i) {
      const std::size_t t = order_[i];
      for (std::int32_t v : mesh.tets[t]) {
        if (new_id_[v] < 0) {
          new_id_[v] = next++;
          cells.xyz.insert(cells.xyz.end(), mesh.points[v].begin(), mesh.points[v].end());
          cells.global_ids.push_back(v);
        }
        cells.connectivity.push_back(new_id_[v]);
      }
      add_cell(output_, region_, t, cells);
    }
    for (std::size_t i = start_[s]; i < start_[s + 1]; ++i)
      for (std::int32_t v : mesh.tets[order_[i]]) new_id_[v] = -1;
    return cells;
  }

 private:
  std::size_t slot(std::size_t t) const { return static_cast<std::size_t>(piece_of(output_.mesh, t) - lowest_); }

  const MeshOutput& output_;
  const std::vector<std::int32_t>& region_;
  std::vector<std::int64_t> new_id_;
  std::vector<std::size_t> start_;  // order_[start_[s], start_[s + 1]): the tets of piece lowest_ + s
  std::vector<std::uint32_t> order_;
  int lowest_ = 0;
};

}  // namespace

namespace {

// New ids for a piece file's points in order of first use: through an array over the span of
// their old ids when it is compact (a bulk: the piece's surface points and its own Steiner
// points), else through their places among the ids, sorted once (the seams' tets use points
// from everywhere, and no rank holds an array over the whole mesh's ids).
class FirstUseIds {
 public:
  explicit FirstUseIds(const std::vector<TetsWithRegion>& blocks) {
    std::size_t refs = 0;
    for (const TetsWithRegion& block : blocks)
      for (const Tet& t : *block.tets)
        for (std::int32_t v : t) {
          const std::int64_t id = block.ids(v);
          low_ = std::min(low_, id), high_ = std::max(high_, id), ++refs;
        }
    if (refs == 0) return;
    const auto span = static_cast<std::uint64_t>(high_ - low_) + 1;
    if (span <= 8 * static_cast<std::uint64_t>(refs)) {
      by_offset_.assign(static_cast<std::size_t>(span), -1);
      return;
    }
    for (const TetsWithRegion& block : blocks)
      for (const Tet& t : *block.tets)
        for (std::int32_t v : t) sorted_.push_back(block.ids(v));
    std::sort(sorted_.begin(), sorted_.end());
    sorted_.erase(std::unique(sorted_.begin(), sorted_.end()), sorted_.end());
    by_place_.assign(sorted_.size(), -1);
  }
  // The new id of the mesh's point v, given it now when it has none.
  std::int64_t operator()(std::int64_t v, std::vector<std::int64_t>& global_ids) {
    std::int64_t& id =
        by_offset_.empty()
            ? by_place_[static_cast<std::size_t>(std::lower_bound(sorted_.begin(), sorted_.end(), v) - sorted_.begin())]
            : by_offset_[static_cast<std::size_t>(v - low_)];
    if (id < 0) id = static_cast<std::int64_t>(global_ids.size()), global_ids.push_back(v);
    return id;
  }

 private:
  std::int64_t low_ = INT64_MAX, high_ = INT64_MIN;
  std::vector<std::int64_t> by_offset_;
  std::vector<std::int64_t> sorted_;
  std::vector<std::int64_t> by_place_;
};

}  // namespace

VtuCells piece_file_cells(int piece, const std::vector<TetsWithRegion>& blocks) {
  FirstUseIds new_id(blocks);
  VtuCells cells;
  for (const TetsWithRegion& block : blocks) {
    if (block.region->size() != block.tets->size()) throw InternalError("a block's regions do not match its tets");
    for (std::size_t t = 0; t < block.tets->size(); ++t) {
      for (std::int32_t v : (*block.tets)[t]) cells.connectivity.push_back(new_id(block.ids(v), cells.global_ids));
      cells.offsets.push_back(static_cast<std::int64_t>(cells.connectivity.size()));  // where the cell ends
      cells.types.push_back(10);                                                      // VTK_TETRA
      cells.piece.push_back(piece);
      cells.region.push_back((*block.region)[t]);
    }
  }
  return cells;
}

void write_vtu_file(const VtuCellsView& cells, const std::string& path, const std::string& shown) {
  VtuFileWriter file(path, shown, cells.xyz.size / 3, cells.types.size, cells.global_ids.size > 0);
  const auto as_is = [&](VtuArray which, auto run) {
    file.array(which, [&](ByteSink& out) { out.bytes(run.data, run.size * sizeof(*run.data)); });
  };
  as_is(VtuArray::points, cells.xyz);
  as_is(VtuArray::connectivity, cells.connectivity);
  as_is(VtuArray::offsets, cells.offsets);
  as_is(VtuArray::types, cells.types);
  as_is(VtuArray::piece, cells.piece);
  as_is(VtuArray::region, cells.region);
  if (cells.global_ids.size > 0) as_is(VtuArray::global_ids, cells.global_ids);
  file.close();
}

void write_vtu(const VtuRows& rows, const std::string& path, const std::string& shown) {
  VtuFileWriter file(path, shown, rows.points, rows.tets, false);
  file.array(VtuArray::points, [&](ByteSink& out) { rows.write(out, RowLines::vtu_points); });
  file.array(VtuArray::connectivity, [&](ByteSink& out) { rows.write(out, RowLines::vtu_connectivity); });
  file.cell_layout();
  file.array(VtuArray::piece, [&](ByteSink& out) { rows.write(out, RowLines::vtu_piece); });
  file.array(VtuArray::region, [&](ByteSink& out) { rows.write(out, RowLines::vtu_region); });
  file.close();
}

VtuRows vtu_rows(const MeshOutput& output) {
  const TetMesh& mesh = output.mesh;
  VtuRows rows;
  rows.points = mesh.points.size(), rows.tets = mesh.tets.size();
  rows.write = [&mesh](ByteSink& out, RowLines lines) {
    if (formats_points(lines)) return write_row_lines(out, lines, {mesh.points.data(), mesh.points.size(), 0, 0});
    std::vector<std::int32_t> column;  // the regions, or the pieces when the mesh has none (-1)
    if (lines == RowLines::vtu_region) column = region_of_tets(mesh);
    if (lines == RowLines::vtu_piece && mesh.piece.empty()) column.assign(mesh.tets.size(), -1);
    const std::int32_t* piece = mesh.piece.empty() ? column.data() : mesh.piece.data();
    write_row_lines(out, lines, {mesh.tets.data(), mesh.tets.size(), 0, 0, column.data(), piece});
  };
  return rows;
}

PieceArrays arrays_of(const VtuCellsView& cells) {
  return {bytes_of(cells.xyz),   bytes_of(cells.connectivity), bytes_of(cells.offsets),   bytes_of(cells.types),
          bytes_of(cells.piece), bytes_of(cells.region),       bytes_of(cells.global_ids)};
}

namespace {

// The cells, or nothing when the arrays do not fit together (lost or cut bytes).
std::optional<VtuCellsView> vtu_cells_from(const PieceArrays& arrays) {
  VtuCellsView cells;
  if (!as_runs(arrays, cells.xyz, cells.connectivity, cells.offsets, cells.types, cells.piece, cells.region,
               cells.global_ids))
    return std::nullopt;
  const std::size_t tets = cells.types.size;
  if (cells.xyz.size % 3 != 0 || cells.connectivity.size != 4 * tets || cells.offsets.size != tets ||
      cells.piece.size != tets || cells.region.size != tets ||
      (cells.global_ids.size != 0 && cells.global_ids.size != cells.xyz.size / 3))
    return std::nullopt;
  return cells;
}

}  // namespace

void write_piece_file(MeshFormat format, const PieceArrays& arrays, const std::string& path, const std::string& shown) {
  if (format == MeshFormat::pvtu) {
    const std::optional<VtuCellsView> cells = vtu_cells_from(arrays);
    if (!cells) throw OutputError("the cells of '" + shown + "' came incomplete");
    write_vtu_file(*cells, path, shown);
  } else if (format == MeshFormat::msh_parts || format == MeshFormat::msh_parts_binary) {
    const std::optional<MshPartView> part = msh_part_from(arrays);
    if (!part) throw OutputError("the partition of '" + shown + "' came incomplete");
    write_msh_part(*part, path, shown);
  } else {
    throw InternalError("format " + mesh_format_name(format) + " has no piece files");
  }
}

// ---------------------------------------------------------------------------------------------

std::vector<std::int32_t> region_of_tets(const TetMesh& mesh) {
  const std::vector<Tet> computed = mesh.neighbours.size() == mesh.tets.size()
                                        ? std::vector<Tet>{}
                                        : compute_neighbours(mesh.tets, mesh.points.size());
  const std::vector<Tet>& neighbours = computed.empty() ? mesh.neighbours : computed;
  std::vector<std::int32_t> label;
  label_tet_regions(
      neighbours, [](std::size_t) { return true; }, [](std::size_t, int) { return true; }, label);
  for (std::int32_t& l : label) ++l;
  return label;
}

std::vector<int> pieces_in(const MeshOutput& output) {
  std::vector<int> pieces;
  if (output.mesh.piece.empty()) return output.mesh.tets.empty() ? pieces : std::vector<int>{-1};
  std::vector<char> seen;
  bool seams = false;
  for (std::int32_t p : output.mesh.piece) {
    if (p < 0) {
      seams = true;
      continue;
    }
    if (static_cast<std::size_t>(p) >= seen.size()) seen.resize(static_cast<std::size_t>(p) + 1, 0);
    seen[p] = 1;
  }
  if (seams) pieces.push_back(-1);
  for (std::size_t p = 0; p < seen.size(); ++p)
    if (seen[p]) pieces.push_back(static_cast<int>(p));
  return pieces;
}

void write_pvtu(const MeshOutput&, const std::string& path, const std::vector<std::string>& piece_files) {
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      "<PUnstructuredGrid GhostLevel=\"0\">\n"
      "<PPointData GlobalIds=\"" +
      std::string(kGlobalPointIds) + "\">\n<PDataArray type=\"Int64\" Name=\"" + kGlobalPointIds +
      "\"/>\n</PPointData>\n"
      "<PPoints>\n<PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n</PPoints>\n"
      "<PCellData Scalars=\"piece\">\n<PDataArray type=\"Int32\" Name=\"piece\"/>\n"
      "<PDataArray type=\"Int32\" Name=\"region\"/>\n</PCellData>\n";
  for (const std::string& file : piece_files) xml += "<Piece Source=\"" + xml_escaped(file) + "\"/>\n";
  xml += "</PUnstructuredGrid>\n</VTKFile>\n";
  BufferedFile out(path);
  out.bytes(xml.data(), xml.size());
  out.close();
}

void write_medit(const MeshRows& rows, const std::vector<Triangle>& boundary, std::size_t split_from,
                 const std::string& path, const std::string& shown) {
  BufferedFile out(path, shown);
  out.text("MeshVersionFormatted 2\nDimension 3\nVertices\n");
  out.integer(static_cast<std::int64_t>(rows.points));
  out.newline();
  rows.write(out, RowLines::medit_vertex, 0);
  out.text("Triangles\n");
  out.integer(static_cast<std::int64_t>(boundary.size()));
  out.newline();
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    for (std::int32_t v : boundary[i]) out.integer(v + 1), out.space();
    out.text(i < split_from ? "1\n" : "2\n");
  }
  out.text("Tetrahedra\n");
  out.integer(static_cast<std::int64_t>(rows.tets));
  out.newline();
  rows.write(out, RowLines::medit_tet, 0);
  out.text("End\n");
  out.close();
}

MeshRows mesh_rows(const MeshOutput& output, bool box) {
  const TetMesh& mesh = output.mesh;
  MeshRows rows;
  rows.points = mesh.points.size(), rows.tets = mesh.tets.size();
  if (box) rows.box = bounds_of(mesh.points);
  rows.write = [&mesh](BufferedFile& out, RowLines lines, std::int64_t number_from) {
    if (formats_points(lines)) return write_row_lines(out, lines, {mesh.points.data(), mesh.points.size(), 0, 0});
    std::vector<std::int32_t> region;
    if (lines == RowLines::medit_tet) region = region_of_tets(mesh);
    write_row_lines(out, lines, {mesh.tets.data(), mesh.tets.size(), 0, number_from, region.data()});
  };
  return rows;
}

// ---------------------------------------------------------------------------------------------
// Choosing formats and publishing their files

namespace {

struct FormatInfo {
  MeshFormat format;
  const char* name;
  const char* extension;  // of the file -o may name
};
constexpr FormatInfo kFormats[] = {{MeshFormat::tetgen, "tetgen", ".node"},
                                   {MeshFormat::vtu, "vtu", ".vtu"},
                                   {MeshFormat::pvtu, "pvtu", ".pvtu"},
                                   {MeshFormat::msh, "msh", ".msh"},
                                   {MeshFormat::msh_binary, "msh-binary", ""},
                                   {MeshFormat::msh_parts, "msh-parts", ""},
                                   {MeshFormat::msh_parts_binary, "msh-parts-binary", ""},
                                   {MeshFormat::medit, "medit", ".mesh"},
                                   {MeshFormat::xdmf, "xdmf", ".xdmf"}};

bool ends_with(const std::string& s, const std::string& tail) {
  return !tail.empty() && s.size() > tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string piece_file(const std::string& prefix, int piece) {
  return prefix + (piece < 0 ? std::string("_seams.vtu") : "_p" + std::to_string(piece) + ".vtu");
}

// Whether a file name is head + a number (no leading zero) + tail.
bool is_numbered_name(const std::string& name, const std::string& head, const std::string& tail) {
  if (name.size() <= head.size() + tail.size() || name.compare(0, head.size(), head) != 0 ||
      name.compare(name.size() - tail.size(), tail.size(), tail) != 0)
    return false;
  const std::string digits = name.substr(head.size(), name.size() - head.size() - tail.size());
  return digits.find_first_not_of("0123456789") == std::string::npos && (digits == "0" || digits[0] != '0');
}

// Whether a file name is one of piece_file(base, i)'s.
bool is_piece_file_name(const std::string& name, const std::string& base) {
  return name == base + "_seams.vtu" || is_numbered_name(name, base + "_p", ".vtu");
}

}  // namespace

bool partition_file_prefix(const std::string& path, std::string& prefix) {
  const std::size_t underscore = path.find_last_of('_');
  if (underscore == std::string::npos || !is_numbered_name(path, path.substr(0, underscore + 1), ".msh")) return false;
  prefix = path.substr(0, underscore);
  return true;
}

std::string partition_file(const std::string& prefix, std::size_t partition) {
  return prefix + "_" + std::to_string(partition) + ".msh";
}

namespace {

// Whether a file is one of partition_file(base, i)'s: by its name, and by its head, so that a
// single .msh another run wrote at BASE_2 is never taken for a partition.
bool is_partition_file(const std::string& directory, const std::string& name, const std::string& base) {
  if (!is_numbered_name(name, base + "_", ".msh")) return false;
  std::ifstream in(directory + "/" + name, std::ios::binary);
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head.find("\n$PartitionedEntities\n") != std::string::npos;
}

void write_piece_files(MeshFormat format, const std::vector<PieceFile>& files, const PieceArraysOf& arrays_of,
                       const PieceFilesWrite& write) {
  if (write)
    write(format, files, arrays_of);
  else
    for (const PieceFile& file : files) write_piece_file(format, arrays_of(file.piece), file.temporary, file.shown);
}

// A .pvtu set: one .vtu per piece value, then the index naming them. The piece files' temporaries
// are made first and written together (by every rank when the driver deals them out; by the ranks
// keeping its parts when the mesh is spread), inside the index's add, so that a failure of any
// removes them all.
void add_pvtu_files(OutputSet& set, const MeshOutput& output, const std::string& prefix, const RankWriters& writers) {
  // The index names its piece files relative to its own directory.
  const std::string base = prefix.substr(prefix.find_last_of('/') + 1);
  const bool spread = static_cast<bool>(writers.spread_piece_files);
  std::vector<std::string> sources;
  std::vector<PieceFile> files;
  for (int piece : spread ? writers.spread_pieces : pieces_in(output)) {
    const std::string final_path = piece_file(prefix, piece);
    set.add(final_path, [&](const std::string& tmp) { files.push_back({piece, tmp, final_path}); });
    sources.push_back(piece_file(base, piece));
  }
  set.add(format_paths(MeshFormat::pvtu, prefix).front(), [&](const std::string& tmp) {
    if (spread) {
      writers.spread_piece_files(MeshFormat::pvtu, files, output);
      write_pvtu(output, tmp, sources);
      return;
    }
    const std::vector<std::int32_t> region = region_of_tets(output.mesh);  // once for all the files
    PieceCells cells(output, region);
    VtuCells current;  // the last piece's cells, kept until the next is asked for
    write_piece_files(
        MeshFormat::pvtu, files,
        [&](int piece) {
          current = cells.of(piece);
          return arrays_of(current.view());
        },
        writers.piece_files);
    write_pvtu(output, tmp, sources);
  });
  // Piece files of an earlier .pvtu at this prefix that this one does not name (it had more
  // pieces) go with the previous set.
  set.supersede(directory_of(prefix), [base](const std::string& name) { return is_piece_file_name(name, base); });
}

// An MSH set: one file per partition (msh.hpp). As for a .pvtu set, every temporary is made
// first and the files are written together inside the last file's add (by the ranks keeping the
// mesh's parts when it is spread).
void add_msh_partition_files(OutputSet& set, MeshFormat format, const MeshOutput& output, const std::string& prefix,
                             const RankWriters& writers) {
  const bool spread = static_cast<bool>(writers.spread_piece_files);
  const std::vector<int> pieces = spread ? msh_partition_order(writers.spread_pieces) : msh_partition_pieces(output);
  std::vector<PieceFile> files;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const std::string final_path = partition_file(prefix, i + 1);
    set.add(final_path, [&](const std::string& tmp) {
      files.push_back({pieces[i], tmp, final_path});
      if (files.size() < pieces.size()) return;
      if (spread) return writers.spread_piece_files(format, files, output);
      MshPartitions partitions(output, format == MeshFormat::msh_parts_binary);
      write_piece_files(
          format, files, [&](int piece) { return arrays_of(partitions.of(piece)); }, writers.piece_files);
    });
  }
  // Partition files of an earlier set at this prefix that had more partitions go with it.
  const std::string directory = directory_of(prefix), base = prefix.substr(prefix.find_last_of('/') + 1);
  set.supersede(directory,
                [directory, base](const std::string& name) { return is_partition_file(directory, name, base); });
}

}  // namespace

std::vector<FileFamily> mesh_named_files(MeshFormat format, const std::string& prefix) {
  const std::string directory = directory_of(prefix), base = prefix.substr(prefix.find_last_of('/') + 1);
  switch (format) {
    case MeshFormat::pvtu:
      return {{directory, [base](const std::string& name) { return is_piece_file_name(name, base); }}};
    case MeshFormat::msh_parts:
    case MeshFormat::msh_parts_binary:
      return {{directory, [base](const std::string& name) { return is_numbered_name(name, base + "_", ".msh"); }}};
    default:
      return {};
  }
}

const std::vector<std::string>& mesh_format_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const FormatInfo& f : kFormats) n.push_back(f.name);
    return n;
  }();
  return names;
}

MeshFormat mesh_format(const std::string& name) {
  for (const FormatInfo& f : kFormats)
    if (name == f.name) return f.format;
  std::string valid;
  for (const FormatInfo& f : kFormats) valid += std::string(valid.empty() ? "" : ", ") + f.name;
  throw OptionError("unknown mesh format '" + name + "' (known: " + valid + ")");
}

std::string mesh_format_name(MeshFormat format) {
  for (const FormatInfo& f : kFormats)
    if (f.format == format) return f.name;
  return "?";
}

bool split_format_extension(const std::string& path, MeshFormat& format, std::string& prefix) {
  for (const FormatInfo& f : kFormats)
    if (ends_with(path, f.extension)) {
      format = f.format;
      prefix = path.substr(0, path.size() - std::strlen(f.extension));
      return true;
    }
  return false;
}

std::vector<std::string> format_paths(MeshFormat format, const std::string& prefix) {
  switch (format) {
    case MeshFormat::tetgen: {
      std::vector<std::string> paths;
      for (TetgenFile file : {TetgenFile::node, TetgenFile::ele, TetgenFile::face, TetgenFile::neigh})
        paths.push_back(prefix + extension(file));
      return paths;
    }
    case MeshFormat::vtu:
      return {prefix + ".vtu"};
    case MeshFormat::pvtu:
      return {prefix + ".pvtu"};
    case MeshFormat::msh:
      return {prefix + ".msh"};
    case MeshFormat::msh_binary:
      return {prefix + ".msh"};
    case MeshFormat::msh_parts:
    case MeshFormat::msh_parts_binary:
      return {partition_file(prefix, 1)};
    case MeshFormat::medit:
      return {prefix + ".mesh"};
    case MeshFormat::xdmf:
      return xdmf_paths(prefix);
  }
  return {};
}

void add_mesh_files(OutputSet& set, MeshFormat format, const MeshOutput& output, const std::string& prefix,
                    const RankWriters& writers) {
  const std::string path = format_paths(format, prefix).front();
  switch (format) {
    case MeshFormat::tetgen:
      if (writers.spread_rows) return writers.spread_rows(set, format, output, prefix);
      add_tetgen_files(set, output.mesh, output.boundary, prefix, output.split_from, writers.tetgen_lines);
      return;
    case MeshFormat::vtu:
      if (writers.spread_rows) return writers.spread_rows(set, format, output, prefix);
      set.add(path, [&](const std::string& tmp) { write_vtu(vtu_rows(output), tmp, path); });
      return;
    case MeshFormat::msh:
    case MeshFormat::msh_binary:
      if (writers.spread_rows) return writers.spread_rows(set, format, output, prefix);
      set.add(path, [&](const std::string& tmp) {
        write_msh(mesh_rows(output, true), output.boundary, output.split_from, tmp, path,
                  format == MeshFormat::msh_binary);
      });
      return;
    case MeshFormat::medit:
      if (writers.spread_rows) return writers.spread_rows(set, format, output, prefix);
      set.add(path, [&](const std::string& tmp) {
        write_medit(mesh_rows(output, false), output.boundary, output.split_from, tmp, path);
      });
      return;
    case MeshFormat::xdmf:
      add_xdmf_files(set, output, prefix, writers.hdf5);
      return;
    case MeshFormat::pvtu:
      add_pvtu_files(set, output, prefix, writers);
      return;
    case MeshFormat::msh_parts:
    case MeshFormat::msh_parts_binary:
      add_msh_partition_files(set, format, output, prefix, writers);
      return;
  }
}

}  // namespace partet
