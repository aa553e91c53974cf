// TetGen's file formats: .node .ele .face .neigh, numbered from 0. Every file of a set ends
// with the line "# partet mesh ID", the same ID (a fingerprint of the mesh) in all four, so a
// set mixed from different runs can be told apart.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "common/point_ids.hpp"
#include "io/output_set.hpp"
#include "partet/mesh_types.hpp"

namespace partet {

enum class TetgenFile { node, ele, face, neigh };

const char* extension(TetgenFile file);  // ".node", ...

// A fingerprint of the mesh's points, tets and boundary faces: the ID written into its files.
std::string mesh_id(const TetMesh& mesh, const std::vector<Triangle>& boundary_faces);

// The same ID from the fingerprints of the three arrays' rows. A fingerprint of rows A then B is
// combine(of A, of B), so the ranks keeping a spread mesh's parts each take their own rows' and
// rank 0 joins them in row order, without the whole mesh.
struct RowsFingerprint {
  std::uint64_t hash = 0, words = 0;
};
RowsFingerprint fingerprint_rows(TetgenFile file, const char* data, std::size_t count);  // rows as packed
template <class Row>
RowsFingerprint fingerprint_rows(TetgenFile file, const std::vector<Row>& rows) {
  return fingerprint_rows(file, reinterpret_cast<const char*>(rows.data()), rows.size());
}
// Tets whose ids go through `ids`: the fingerprint of their rows in the mesh's ids. An id past
// 2^32 folds its high bits into the next id's place; below 2^31 this is fingerprint_rows's.
RowsFingerprint fingerprint_tets(const std::vector<Tet>& tets, const PointIds& ids);
RowsFingerprint combine(const RowsFingerprint& first, const RowsFingerprint& then);
std::string mesh_id(const RowsFingerprint& points, const RowsFingerprint& tets, const RowsFingerprint& faces);

// The body of one file: `count` packed rows (3 doubles for .node, 4 ids for .ele and .neigh,
// 3 ids for .face), each written as the line "index values[ marker]".
struct TetgenRows {
  TetgenFile file = TetgenFile::node;
  const char* data = nullptr;
  std::size_t count = 0;
  std::size_t split_from = SIZE_MAX;  // .face: marker 1 before this row, 2 from it on
};
std::size_t row_bytes(TetgenFile file);  // bytes of one packed row

// Appends the lines of rows [first, first + count) to `text`; `data` points to row `first`.
void append_tetgen_lines(std::string& text, TetgenFile file, const char* data, std::size_t first, std::size_t count,
                         std::size_t split_from);

// Writes the lines of all rows to `out`, in order. Empty: formatted here, one after another;
// the MPI driver's has every rank format a block of them at the same time.
class BufferedFile;
using TetgenLines = std::function<void(const TetgenRows& rows, BufferedFile& out)>;
// The lines of rows [first, first + count) straight into `out` (the empty TetgenLines).
void write_tetgen_lines(const TetgenRows& rows, std::size_t first, std::size_t count, BufferedFile& out);

// The lines of rows [first, first + count) into `out`; `data` points to row `first`.
void write_tetgen_lines(BufferedFile& out, TetgenFile file, const char* data, std::size_t first, std::size_t count,
                        std::size_t split_from = SIZE_MAX);

// Whether a file is complete on return, or finished by a writing thread while the next one is
// formatted (then finish_background_writes, io/buffered_file.hpp, waits for it; OutputSet's
// publish does).
enum class Closing { now, in_background };

// Writes one file of the set to `path` (errors name `shown_path`). Coordinates use 17
// significant digits so they read back bit-identical; .face holds the boundary faces with marker 1,
// or 2 from split_from on (the parts of input triangles split by points on the surface).
void write_tetgen_file(TetgenFile file, const TetMesh& mesh, const std::vector<Triangle>& boundary_faces,
                       const std::string& id, const std::string& path, const std::string& shown_path,
                       std::size_t split_from = SIZE_MAX, const TetgenLines& lines = {},
                       Closing closing = Closing::now);

// Writes one file of packed rows to `path` (errors name `shown`): a header line, one line per row
// (by `lines`; empty: here), and the id line.
void write_tetgen_file(const TetgenRows& rows, const TetgenLines& lines, const std::string& id, const std::string& path,
                       const std::string& shown, Closing closing);

// Writes one file of `count` rows to `path` (errors name `shown`), its lines by write_lines, in
// order: for a mesh whose rows come from several places (a spread mesh's owners).
void write_tetgen_file(TetgenFile file, std::size_t count, const std::string& id, const std::string& path,
                       const std::string& shown, const std::function<void(BufferedFile&)>& write_lines,
                       Closing closing);

// Adds PREFIX.node, .ele, .face and .neigh to an output set (published together).
void add_tetgen_files(OutputSet& set, const TetMesh& mesh, const std::vector<Triangle>& boundary_faces,
                      const std::string& prefix, std::size_t split_from = SIZE_MAX, const TetgenLines& lines = {});

// Everything a set of TetGen files holds. Accepts 0- or 1-based numbering as TetGen does.
struct TetgenFileSet {
  TetMesh mesh;                 // .node and .ele; neighbours computed from the tets
  std::vector<Triangle> faces;  // .face, when present
  std::vector<Tet> neighbours;  // .neigh as written, when present
  bool has_faces = false, has_neighbours = false;
  std::vector<std::pair<std::string, std::string>> ids;  // (file, its set ID or "") of each file read
  bool faces_outward = false;                            // the faces are promised outward (besides by a set ID)
  std::string faces_named = "the .face file does";       // in messages (sets are also read from MSH files)
};
// Throws InputError on a missing .node/.ele or malformed content.
TetgenFileSet read_tetgen_set(const std::string& prefix);

// PREFIX.node and PREFIX.ele (and PREFIX.face, if present, into boundary_faces).
TetMesh read_tetgen_files(const std::string& prefix, std::vector<Triangle>* boundary_faces = nullptr);

// Reading one file in parts, each part by another process (a check on several ranks): the
// header's count, where the rows begin (after the header line), the first row's index (TetGen
// numbers from 0 or 1; 0 when there is no row) and the file's size. Throws InputError on a
// missing file or a malformed header (10-node tets are refused here).
struct TetgenFileLayout {
  std::int64_t count = 0, first_index = 0;
  std::uint64_t rows_begin = 0, size = 0;
};
TetgenFileLayout tetgen_file_layout(const std::string& path, TetgenFile file);

// Where part `part` of `parts` of the rows begins: the first line starting at or after its share
// of the bytes (part 0: rows_begin; part `parts`: the end). Each part is whole lines.
std::uint64_t tetgen_part_begin(const std::string& path, const TetgenFileLayout& layout, int part, int parts);

// The rows whose lines lie in bytes [begin, end) of the file, as written: each row's own index,
// its coordinates (.node) or values (4 per row for .ele and .neigh, 3 for .face, vertex or tet
// indices as written) and .face's boundary markers (1 when there is none); and the set ID when
// its line ("# partet mesh ID") is in the part. Throws InputError naming the byte of a malformed row.
struct TetgenRowsRead {
  std::vector<std::int64_t> index;
  std::vector<Point3> points;
  std::vector<std::int64_t> values;
  std::vector<std::int32_t> markers;
  std::string id;
};
TetgenRowsRead read_tetgen_rows(const std::string& path, TetgenFile file, std::uint64_t begin, std::uint64_t end);

}  // namespace partet
