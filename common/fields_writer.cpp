// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/fields_writer.hpp"

#include <hdf5.h>

#include "common/hdf5_handle.hpp"

#include <unistd.h>
#include <charconv>
#include <cstdio>
#include <numeric>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>

#include "common/atomic_file.hpp"
#include "common/error.hpp"

namespace arlequin {

// The header stores the file id as int64 so that hdf5.h (and, for the MPI build, mpi.h)
// stays out of everything that includes it.
static_assert(std::is_same_v<hid_t, std::int64_t>);
// Vec3 spans are written as n x 3 doubles without copying.
static_assert(sizeof(Vec3) == 3 * sizeof(double) && std::is_standard_layout_v<Vec3>);

namespace {

// HDF5 returns negative ids / statuses on failure; the error stack is silenced (see the
// constructor), so the message says which operation failed on which object.
template <class T>
T checked(T result, const std::filesystem::path& file, std::string_view action, std::string_view object) {
  if (result < 0)
    throw RunError("HDF5: cannot " + std::string(action) + " '" + std::string(object) + "' in '" + file.string() +
                   "'");
  return result;
}

using Handle = Hdf5Handle;

// Link creation properties that create missing intermediate groups, so a dataset path
// like /frames/000003/particles/point/velocity can be written in one call.
Handle intermediate_groups(const std::filesystem::path& file, std::string_view object) {
  Handle lcpl(checked(H5Pcreate(H5P_LINK_CREATE), file, "create link properties for", object), H5Pclose);
  checked(H5Pset_create_intermediate_group(lcpl, 1), file, "set link properties for", object);
  return lcpl;
}

struct CellType {
  const char* xdmf_name;
  std::size_t nodes;
};

CellType cell_type(FieldsWriter::CellKind kind) {
  switch (kind) {
    case FieldsWriter::CellKind::Vertex: return {"Polyvertex", 1};
    case FieldsWriter::CellKind::Line: return {"Polyline", 2};
    case FieldsWriter::CellKind::Triangle: return {"Triangle", 3};
    case FieldsWriter::CellKind::Tetrahedron: return {"Tetrahedron", 4};
    case FieldsWriter::CellKind::Tetrahedron10: return {"Tetrahedron_10", 10};
  }
  throw std::logic_error("FieldsWriter: unknown cell kind");
}

std::string xml_escaped(std::string_view text) {
  std::string out;
  for (const char ch : text) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += ch;
    }
  }
  return out;
}

// Shortest text that reads back to the same double, independent of the locale.
std::string number_text(double value) {
  char buffer[32];
  return std::string(buffer, std::to_chars(buffer, buffer + sizeof buffer, value).ptr);
}

void replace_all(std::string& text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
}

// Stands for the HDF5 file's name in frames_index(): a control character, which no XML holds.
constexpr const char* file_token = "\x1f:";

// Frame k's group in the HDF5 file, "/frames/000042".
std::string frame_group(std::size_t k) {
  char path[32];
  std::snprintf(path, sizeof path, "/frames/%06zu", k);
  return path;
}
// How each frame's XDMF starts (finish_frame), which frames_index() counts.
constexpr const char* frame_grid_start = "<Grid Name=\"frame_";

void check_name(std::string_view kind, const std::string& name) {
  if (name.empty() || name.find('/') != std::string::npos)
    throw std::logic_error("FieldsWriter: bad " + std::string(kind) + " name '" + name + "'");
}

}  // namespace

// Values to store: `rows` tuples of `components` elements of HDF5 memory type `type`.
struct FieldsWriter::Column {
  Column(std::span<const double> values)
      : data(values.data()), rows(values.size()), components(1), type(H5T_NATIVE_DOUBLE), xdmf_type("Float"), precision(8) {}
  Column(std::span<const Vec3> values)
      : data(values.data()), rows(values.size()), components(3), type(H5T_NATIVE_DOUBLE), xdmf_type("Float"), precision(8) {}
  Column(std::span<const std::int32_t> values)
      : data(values.data()), rows(values.size()), components(1), type(H5T_NATIVE_INT32), xdmf_type("Int"), precision(4) {}
  Column(std::span<const std::int64_t> values, std::size_t per_row)
      : data(values.data()), rows(values.size() / per_row), components(per_row), type(H5T_NATIVE_INT64), xdmf_type("Int"),
        precision(8) {}

  const void* data;
  std::size_t rows;
  std::size_t components;  // 1: one-dimensional dataset; otherwise rows x components
  hid_t type;
  const char* xdmf_type;
  int precision;
};

FieldsWriter::FieldsWriter(std::filesystem::path h5_path, std::filesystem::path xdmf_path)
    : h5_path_(std::move(h5_path)), part_path_(h5_path_), xdmf_path_(std::move(xdmf_path)) {
  part_path_ += ".part." + std::to_string(::getpid());  // one per writing process (MPI ranks)
  h5_reference_ = reference_to(part_path_);
  // Every failure becomes a RunError naming the operation; the library's own stack dump on
  // stderr would only duplicate it (this setting is process-wide, which is what we want).
  checked(H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr), part_path_, "silence error printing for", "file");
  if (h5_path_.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(h5_path_.parent_path(), ec);
    if (ec) throw RunError("cannot create directory '" + h5_path_.parent_path().string() + "': " + ec.message());
  }
  file_ = checked(H5Fcreate(part_path_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), part_path_, "create", "file");
}

FieldsWriter::~FieldsWriter() {
  try {
    close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "arlequin: %s\n", e.what());
  }
}

void FieldsWriter::begin_frame(double time) {
  if (file_ < 0) throw std::logic_error("FieldsWriter::begin_frame: writer is closed");
  if (in_frame_) throw std::logic_error("FieldsWriter::begin_frame: previous frame not ended");
  const std::string group_path = frame_group(frame_count_);
  const char* path = group_path.c_str();
  const Handle group(checked(H5Gcreate2(file_, path, intermediate_groups(part_path_, path), H5P_DEFAULT, H5P_DEFAULT),
                             part_path_, "create group", path),
                     H5Gclose);
  const Handle space(checked(H5Screate(H5S_SCALAR), part_path_, "create dataspace for", path), H5Sclose);
  const Handle attribute(
      checked(H5Acreate2(group, "time", H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT), part_path_,
              "create time attribute of", path),
      H5Aclose);
  checked(H5Awrite(attribute, H5T_NATIVE_DOUBLE, &time), part_path_, "write time attribute of", path);
  frame_path_ = path;
  frame_time_ = time;
  in_frame_ = true;
}

void FieldsWriter::end_frame() {
  require_frame("end_frame");
  finish_frame();
  checked(H5Fflush(file_, H5F_SCOPE_LOCAL), part_path_, "flush", "file");
  write_xdmf();
}

void FieldsWriter::close() {
  if (file_ < 0) return;
  if (in_frame_) finish_frame();
  // Forget the id first: whatever fails below, close is never attempted twice.
  const hid_t file = std::exchange(file_, -1);
  checked(H5Fclose(file), part_path_, "close", "file");
  std::error_code ec;
  std::filesystem::rename(part_path_, h5_path_, ec);
  if (ec) throw RunError("cannot rename '" + part_path_.string() + "' to '" + h5_path_.string() + "': " + ec.message());
  // The frames now name the renamed file ("<file>:" starts every dataset reference).
  replace_all(frames_xml_, h5_reference_ + ":", reference_to(h5_path_) + ":");
  h5_reference_ = reference_to(h5_path_);
  write_xdmf();
}

std::string FieldsWriter::frames_index(std::size_t frames) const {
  // Each frame's XDMF starts with its collection grid (finish_frame).
  std::size_t end = 0;
  for (std::size_t k = 0; k <= frames && end != std::string::npos; ++k)
    end = frames_xml_.find(frame_grid_start, k == 0 ? 0 : end + 1);
  std::string index = frames_xml_.substr(0, end);
  replace_all(index, h5_reference_ + ":", file_token);
  return index;
}

void FieldsWriter::tag(std::uint64_t run) {
  const Handle space(checked(H5Screate(H5S_SCALAR), part_path_, "create dataspace for", "run"), H5Sclose);
  const Handle attribute(checked(H5Acreate2(file_, "run", H5T_NATIVE_UINT64, space, H5P_DEFAULT, H5P_DEFAULT), part_path_,
                                 "create attribute", "run"),
                         H5Aclose);
  checked(H5Awrite(attribute, H5T_NATIVE_UINT64, &run), part_path_, "write attribute", "run");
}

void FieldsWriter::carry_frames(const std::filesystem::path& earlier, std::uint64_t run, const std::vector<double>& times,
                                const std::string& index) {
  if (file_ < 0 || in_frame_ || frame_count_ > 0) throw std::logic_error("FieldsWriter::carry_frames: only before the first frame");
  if (times.empty()) return;
  if (H5Fis_hdf5(earlier.c_str()) <= 0) throw RunError("'" + earlier.string() + "' is not a readable HDF5 file");
  const Handle source(checked(H5Fopen(earlier.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), earlier, "open", "file"), H5Fclose);
  std::uint64_t theirs = 0;
  if (H5Aexists(source, "run") <= 0 ||
      H5Aread(Handle(checked(H5Aopen(source, "run", H5P_DEFAULT), earlier, "open", "run"), H5Aclose), H5T_NATIVE_UINT64, &theirs) < 0 ||
      theirs != run)
    throw RunError("'" + earlier.string() + "' holds another run's frames");
  try {
    for (std::size_t k = 0; k < times.size(); ++k) {
      const std::string group = frame_group(k);
      const char* path = group.c_str();
      double time = 0.0;
      if (H5Lexists(source, "/frames", H5P_DEFAULT) <= 0 || H5Lexists(source, path, H5P_DEFAULT) <= 0 ||
          H5Aexists_by_name(source, path, "time", H5P_DEFAULT) <= 0)
        throw RunError("'" + earlier.string() + "' has no frame " + std::to_string(k) + " (" + std::to_string(times.size()) + " expected)");
      const Handle attribute(checked(H5Aopen_by_name(source, path, "time", H5P_DEFAULT, H5P_DEFAULT), earlier, "open", path), H5Aclose);
      checked(H5Aread(attribute, H5T_NATIVE_DOUBLE, &time), earlier, "read the time of", path);
      if (time != times[k])
        throw RunError("frame " + std::to_string(k) + " of '" + earlier.string() + "' is at t = " + number_text(time) +
                       " s, not " + number_text(times[k]) + " s: another run's");
      checked(H5Ocopy(source, path, file_, path, H5P_DEFAULT, intermediate_groups(part_path_, path)), part_path_, "copy", path);
    }
  } catch (...) {
    // Leave the file as it was: no frame carried.
    if (H5Lexists(file_, "/frames", H5P_DEFAULT) > 0) H5Ldelete(file_, "/frames", H5P_DEFAULT);
    throw;
  }
  frames_xml_ = index;
  replace_all(frames_xml_, file_token, h5_reference_ + ":");
  frame_times_ = times;
  frame_count_ = times.size();
  checked(H5Fflush(file_, H5F_SCOPE_LOCAL), part_path_, "flush", "file");
  write_xdmf();
}

std::string FieldsWriter::reference_to(const std::filesystem::path& h5_file) const {
  return xml_escaped(std::filesystem::absolute(h5_file)
                         .lexically_relative(std::filesystem::absolute(xdmf_path_).parent_path())
                         .generic_string());
}

void FieldsWriter::add_grid(const std::string& grid, std::span<const Vec3> points, CellKind kind,
                            std::span<const std::int64_t> connectivity) {
  const std::size_t cells = check_grid(grid, points.size(), kind, connectivity);
  const std::string geometry = write_dataset(frame_path_ + "/" + grid + "/points", Column(points));
  add_cells(Grid{grid, geometry, points.size(), cells, {}}, kind, connectivity);
}

void FieldsWriter::add_grid_sharing_points(const std::string& grid, const std::string& points_of_grid, CellKind kind,
                                           std::span<const std::int64_t> connectivity) {
  require_frame("add_grid_sharing_points");
  const Grid& source = grid_named(points_of_grid);
  const std::size_t cells = check_grid(grid, source.points, kind, connectivity);
  add_cells(Grid{grid, source.geometry, source.points, cells, {}}, kind, connectivity);
}

void FieldsWriter::add_point_field(const std::string& grid, const std::string& name, std::span<const double> values) {
  add_field(grid, name, false, Column(values));
}
void FieldsWriter::add_point_field(const std::string& grid, const std::string& name, std::span<const Vec3> values) {
  add_field(grid, name, false, Column(values));
}
void FieldsWriter::add_point_field(const std::string& grid, const std::string& name,
                                   std::span<const std::int32_t> values) {
  add_field(grid, name, false, Column(values));
}
void FieldsWriter::add_cell_field(const std::string& grid, const std::string& name, std::span<const double> values) {
  add_field(grid, name, true, Column(values));
}
void FieldsWriter::add_cell_field(const std::string& grid, const std::string& name, std::span<const Vec3> values) {
  add_field(grid, name, true, Column(values));
}
void FieldsWriter::add_cell_field(const std::string& grid, const std::string& name,
                                  std::span<const std::int32_t> values) {
  add_field(grid, name, true, Column(values));
}

void FieldsWriter::require_frame(const char* operation) const {
  if (!in_frame_) throw std::logic_error(std::string("FieldsWriter::") + operation + ": no open frame");
}

FieldsWriter::Grid& FieldsWriter::grid_named(const std::string& name) {
  for (Grid& grid : grids_) {
    if (grid.name == name) return grid;
  }
  throw std::logic_error("FieldsWriter: no grid '" + name + "' in frame " + frame_path_);
}

std::size_t FieldsWriter::check_grid(const std::string& grid, std::size_t points, CellKind kind,
                                     std::span<const std::int64_t> connectivity) const {
  require_frame("add_grid");
  check_name("grid", grid);
  for (const Grid& other : grids_) {
    if (other.name == grid) throw std::logic_error("FieldsWriter: grid '" + grid + "' added twice to " + frame_path_);
  }
  if (kind == CellKind::Vertex && connectivity.empty()) return points;
  const std::size_t nodes = cell_type(kind).nodes;
  if (connectivity.size() % nodes != 0)
    throw std::logic_error("FieldsWriter: grid '" + grid + "': connectivity size " +
                           std::to_string(connectivity.size()) + " is not a multiple of " + std::to_string(nodes));
  for (const std::int64_t index : connectivity) {
    if (index < 0 || static_cast<std::size_t>(index) >= points)
      throw std::logic_error("FieldsWriter: grid '" + grid + "': point index " + std::to_string(index) + " not in [0, " +
                             std::to_string(points) + ")");
  }
  return connectivity.size() / nodes;
}

void FieldsWriter::add_cells(Grid grid, CellKind kind, std::span<const std::int64_t> connectivity) {
  const CellType type = cell_type(kind);
  // XDMF needs an explicit connectivity even for point clouds: every point its own vertex.
  std::vector<std::int64_t> own_points;
  if (kind == CellKind::Vertex && connectivity.empty()) {
    own_points.resize(grid.points);
    std::iota(own_points.begin(), own_points.end(), std::int64_t{0});
    connectivity = own_points;
  }
  const std::string topology =
      write_dataset(frame_path_ + "/" + grid.name + "/connectivity", Column(connectivity, type.nodes));
  grid.xml = "<Topology TopologyType=\"" + std::string(type.xdmf_name) + "\" NumberOfElements=\"" +
             std::to_string(grid.cells) + "\" NodesPerElement=\"" + std::to_string(type.nodes) + "\">" + topology +
             "</Topology>\n<Geometry GeometryType=\"XYZ\">" + grid.geometry + "</Geometry>\n";
  grids_.push_back(std::move(grid));
}

void FieldsWriter::add_field(const std::string& grid, const std::string& name, bool on_cells, const Column& column) {
  require_frame(on_cells ? "add_cell_field" : "add_point_field");
  check_name("field", name);
  Grid& target = grid_named(grid);
  const std::size_t expected = on_cells ? target.cells : target.points;
  if (column.rows != expected)
    throw std::logic_error("FieldsWriter: field '" + name + "' of grid '" + grid + "' has " +
                           std::to_string(column.rows) + " values for " + std::to_string(expected) +
                           (on_cells ? " cells" : " points"));
  const std::string data =
      write_dataset(frame_path_ + "/" + grid + (on_cells ? "/cell/" : "/point/") + name, column);
  target.xml += "<Attribute Name=\"" + xml_escaped(name) + "\" AttributeType=\"" +
                (column.components == 3 ? "Vector" : "Scalar") + "\" Center=\"" + (on_cells ? "Cell" : "Node") + "\">" +
                data + "</Attribute>\n";
}

std::string FieldsWriter::write_dataset(const std::string& path, const Column& column) const {
  const hsize_t dims[2] = {column.rows, column.components};
  const int rank = column.components == 1 ? 1 : 2;
  const Handle space(checked(H5Screate_simple(rank, dims, nullptr), part_path_, "create dataspace for", path),
                     H5Sclose);
  const Handle dataset(checked(H5Dcreate2(file_, path.c_str(), column.type, space, intermediate_groups(part_path_, path),
                                          H5P_DEFAULT, H5P_DEFAULT),
                               part_path_, "create dataset", path),
                       H5Dclose);
  // An empty selection still needs a buffer in some HDF5 versions: skip the call instead.
  if (column.rows > 0)
    checked(H5Dwrite(dataset, column.type, H5S_ALL, H5S_ALL, H5P_DEFAULT, column.data), part_path_, "write dataset",
            path);
  std::string dimensions = std::to_string(column.rows);
  if (rank != 1) dimensions.append(" ").append(std::to_string(column.components));
  return "<DataItem Dimensions=\"" + dimensions + "\" NumberType=\"" + column.xdmf_type + "\" Precision=\"" +
         std::to_string(column.precision) + "\" Format=\"HDF\">" + h5_reference_ + ":" + xml_escaped(path) +
         "</DataItem>";
}

void FieldsWriter::finish_frame() {
  in_frame_ = false;
  std::string xml = frame_grid_start + frame_path_.substr(frame_path_.rfind('/') + 1) +
                    "\" GridType=\"Collection\" CollectionType=\"Spatial\">\n<Time Value=\"" +
                    number_text(frame_time_) + "\"/>\n";
  for (const Grid& grid : grids_)
    xml += "<Grid Name=\"" + xml_escaped(grid.name) + "\" GridType=\"Uniform\">\n" + grid.xml + "</Grid>\n";
  frames_xml_ += xml + "</Grid>\n";
  frame_times_.push_back(frame_time_);
  grids_.clear();
  ++frame_count_;
}

void FieldsWriter::write_xdmf() const {
  write_file_atomically(xdmf_path_,
                        "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n"
                        "<Grid Name=\"frames\" GridType=\"Collection\" CollectionType=\"Temporal\">\n" +
                            frames_xml_ + "</Grid>\n</Domain>\n</Xdmf>\n");
}

}  // namespace arlequin
