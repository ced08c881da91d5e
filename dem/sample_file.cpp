// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/sample_file.hpp"

#include <hdf5.h>

#include "common/hdf5_handle.hpp"

#include <array>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "common/atomic_file.hpp"
#include "common/error.hpp"

namespace arlequin::dem {
namespace {

constexpr std::string_view format_name = "arlequin sample";
constexpr int format_version = 1;

// Positions are written as n x 3 doubles without copying.
static_assert(sizeof(Vec3) == 3 * sizeof(double) && std::is_standard_layout_v<Vec3>);

using Handle = Hdf5Handle;

// One sample file being written or read. HDF5 reports failures as negative ids and statuses
// (its own error printing is silenced, as in FieldsWriter); check() turns them into errors
// naming the file and the item: RunError while writing, InputError while reading, where
// the file is the user's input.
class SampleIo {
 public:
  SampleIo(std::filesystem::path file, bool reading) : file_(std::move(file)), reading_(reading) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }

  [[noreturn]] void fail(const std::string& what) const {
    const std::string message = "sample file '" + file_.string() + "': " + what;
    if (reading_) throw InputError(message);
    throw RunError(message);
  }
  template <class T>
  T check(T result, const std::string& what) const {
    if (result < 0) fail(what);
    return result;
  }

  // -- writing ----------------------------------------------------------------------------
  void write_dataset(hid_t at, const char* name, hid_t type, std::size_t rows, std::size_t columns,
                     const void* data) const {
    const hsize_t dims[2] = {rows, columns};
    const Handle space(check(H5Screate_simple(columns == 1 ? 1 : 2, dims, nullptr), "dataspace"), H5Sclose);
    const Handle set(check(H5Dcreate2(at, name, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                           std::string("cannot create dataset ") + name),
                     H5Dclose);
    if (rows > 0) check(H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), std::string("cannot write ") + name);
  }
  // count 1: a scalar attribute; 0: an empty one; otherwise a 1-D array.
  void write_attribute(hid_t at, const char* name, hid_t type, std::size_t count, const void* data) const {
    const hsize_t dims[1] = {count};
    const hid_t shape = count == 1 ? H5Screate(H5S_SCALAR) : count == 0 ? H5Screate(H5S_NULL) : H5Screate_simple(1, dims, nullptr);
    const Handle space(check(shape, "dataspace"), H5Sclose);
    const Handle attribute(check(H5Acreate2(at, name, type, space, H5P_DEFAULT, H5P_DEFAULT),
                                 std::string("cannot create attribute ") + name),
                           H5Aclose);
    if (count > 0) check(H5Awrite(attribute, type, data), std::string("cannot write attribute ") + name);
  }
  void write_string(hid_t at, const char* name, std::string_view text) const {
    const Handle type(check(H5Tcopy(H5T_C_S1), "string type"), H5Tclose);
    check(H5Tset_size(type, std::max<std::size_t>(text.size(), 1)), "string type");
    check(H5Tset_strpad(type, H5T_STR_NULLPAD), "string type");
    std::string padded(text);
    padded.resize(std::max<std::size_t>(text.size(), 1), '\0');
    write_attribute(at, name, type, 1, padded.data());
  }

  // -- reading ----------------------------------------------------------------------------
  // A dataset of rows x columns elements of `type` (1-D when columns is 1), T one row of
  // them (Vec3 for three doubles); the number of rows comes from the file.
  template <class T>
  std::vector<T> read_dataset(hid_t at, const char* name, hid_t type, std::size_t columns) const {
    if (H5Lexists(at, name, H5P_DEFAULT) <= 0) fail(std::string("no dataset ") + name);
    const Handle set(check(H5Dopen2(at, name, H5P_DEFAULT), std::string("cannot open dataset ") + name), H5Dclose);
    const Handle space(check(H5Dget_space(set), std::string("dataspace of ") + name), H5Sclose);
    const int rank = H5Sget_simple_extent_ndims(space);
    hsize_t dims[2] = {0, 1};
    if (rank != (columns == 1 ? 1 : 2) || H5Sget_simple_extent_dims(space, dims, nullptr) < 0 || dims[1] != columns)
      fail(std::string("dataset ") + name + " should have " + std::to_string(columns) + " column(s)");
    std::vector<T> out(dims[0]);
    if (!out.empty()) check(H5Dread(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), std::string("cannot read ") + name);
    return out;
  }
  // An attribute of `count` elements (scalar when count is 1); count 0: any length.
  template <class T>
  std::vector<T> read_attribute(hid_t at, const char* name, hid_t type, std::size_t count) const {
    if (H5Aexists(at, name) <= 0) fail(std::string("no attribute ") + name);
    const Handle attribute(check(H5Aopen(at, name, H5P_DEFAULT), std::string("cannot open attribute ") + name),
                           H5Aclose);
    const Handle space(check(H5Aget_space(attribute), std::string("dataspace of ") + name), H5Sclose);
    const hssize_t elements = H5Sget_simple_extent_npoints(space);
    if (elements < 0 || (count > 0 && static_cast<std::size_t>(elements) != count))
      fail(std::string("attribute ") + name + " should have " + std::to_string(count) + " value(s)");
    std::vector<T> out(static_cast<std::size_t>(elements));
    if (!out.empty()) check(H5Aread(attribute, type, out.data()), std::string("cannot read attribute ") + name);
    return out;
  }
  template <class T>
  T read_scalar(hid_t at, const char* name, hid_t type) const {
    return read_attribute<T>(at, name, type, 1)[0];
  }
  std::string read_string(hid_t at, const char* name) const {
    if (H5Aexists(at, name) <= 0) fail(std::string("no attribute ") + name);
    const Handle attribute(check(H5Aopen(at, name, H5P_DEFAULT), std::string("cannot open attribute ") + name),
                           H5Aclose);
    const Handle type(check(H5Aget_type(attribute), std::string("type of ") + name), H5Tclose);
    if (H5Tget_class(type) != H5T_STRING || H5Tis_variable_str(type) != 0)
      fail(std::string("attribute ") + name + " should be a fixed-length string");
    std::string text(H5Tget_size(type), '\0');
    check(H5Aread(attribute, type, text.data()), std::string("cannot read attribute ") + name);
    return text.substr(0, text.find('\0'));
  }

 private:
  std::filesystem::path file_;
  bool reading_;
};

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

// A region as its shape name and numbers: box lower, upper; cylinder base, axis, radius,
// length; sphere center, radius; half_space point, normal.
std::pair<std::string, std::vector<double>> encode(const Region& region) {
  const auto join = [](std::initializer_list<double> values) { return std::vector<double>(values); };
  return std::visit(
      Overloaded{
          [&](const Box& b) {
            return std::pair{std::string("box"), join({b.lower.x, b.lower.y, b.lower.z, b.upper.x, b.upper.y, b.upper.z})};
          },
          [&](const Cylinder& c) {
            return std::pair{std::string("cylinder"), join({c.base.x, c.base.y, c.base.z, c.axis.x, c.axis.y, c.axis.z,
                                                            c.radius, c.length})};
          },
          [&](const Sphere& s) {
            return std::pair{std::string("sphere"), join({s.center.x, s.center.y, s.center.z, s.radius})};
          },
          [&](const HalfSpace& h) {
            return std::pair{std::string("half_space"),
                             join({h.point.x, h.point.y, h.point.z, h.normal.x, h.normal.y, h.normal.z})};
          },
      },
      region.shape());
}

Region decode(const SampleIo& io, const std::string& shape, const std::vector<double>& v) {
  const auto vec = [&](std::size_t k) { return Vec3{v[k], v[k + 1], v[k + 2]}; };
  const auto expect = [&](std::size_t n) {
    if (v.size() != n) io.fail("region '" + shape + "' should have " + std::to_string(n) + " numbers");
  };
  if (shape == "box") {
    expect(6);
    return Region(Box{vec(0), vec(3)});
  }
  if (shape == "cylinder") {
    expect(8);
    return Region(Cylinder{vec(0), vec(3), v[6], v[7]});
  }
  if (shape == "sphere") {
    expect(4);
    return Region(Sphere{vec(0), v[3]});
  }
  if (shape == "half_space") {
    expect(6);
    return Region(HalfSpace{vec(0), vec(3)});
  }
  io.fail("unknown region shape '" + shape + "'");
}

// The scalar numbers of a spec and its report by attribute name: one table for saving and
// loading, so the two cannot drift apart. S and R may be const.
template <class S, class R>
auto double_fields(S& s, R& r) {
  using P = decltype(&s.mean_radius);
  return std::array<std::pair<const char*, P>, 11>{{{"mean_radius", &s.mean_radius},
                                                    {"relative_std", &s.relative_std},
                                                    {"truncation", &s.truncation},
                                                    {"target_compaction", &s.target_compaction},
                                                    {"min_coordination", &s.min_coordination},
                                                    {"bond_tolerance", &s.bond_tolerance},
                                                    {"compaction", &r.compaction},
                                                    {"mean_coordination", &r.mean_coordination},
                                                    {"interior_coordination", &r.interior_coordination},
                                                    {"max_overlap", &r.max_overlap},
                                                    {"seconds", &r.seconds}}};
}

void write_file(const SampleIo& io, hid_t file, const ParticleSet& p, const PackingSpec& spec,
                const PackingReport& report) {
  io.write_string(file, "format", format_name);
  io.write_attribute(file, "version", H5T_NATIVE_INT, 1, &format_version);

  const Handle particles(io.check(H5Gcreate2(file, "particles", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                                  "cannot create group particles"),
                         H5Gclose);
  io.write_dataset(particles, "position", H5T_NATIVE_DOUBLE, p.size(), 3, p.position.data());
  io.write_dataset(particles, "radius", H5T_NATIVE_DOUBLE, p.size(), 1, p.radius.data());

  const Handle packing(
      io.check(H5Gcreate2(file, "packing", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "cannot create group packing"),
      H5Gclose);
  const auto [shape, numbers] = encode(spec.region);
  io.write_string(packing, "region", shape);
  io.write_attribute(packing, "region_numbers", H5T_NATIVE_DOUBLE, numbers.size(), numbers.data());
  for (const auto& [name, value] : double_fields(spec, report))
    io.write_attribute(packing, name, H5T_NATIVE_DOUBLE, 1, value);
  const std::uint64_t count = report.count;
  io.write_attribute(packing, "seed", H5T_NATIVE_UINT64, 1, &spec.seed);
  io.write_attribute(packing, "count", H5T_NATIVE_UINT64, 1, &count);
  io.write_attribute(packing, "fabric_eigenvalues", H5T_NATIVE_DOUBLE, 3, report.fabric_eigenvalues.data());
  std::vector<double> centres;
  std::vector<std::uint64_t> counts;
  for (const auto& [centre, n] : report.radius_histogram) centres.push_back(centre), counts.push_back(n);
  io.write_attribute(packing, "radius_histogram_centre", H5T_NATIVE_DOUBLE, centres.size(), centres.data());
  io.write_attribute(packing, "radius_histogram_count", H5T_NATIVE_UINT64, counts.size(), counts.data());
}

}  // namespace

void save_sample(const std::filesystem::path& path, const ParticleSet& p, const PackingSpec& spec,
                 const PackingReport& report) {
  const std::filesystem::path tmp = temporary_path_for(path);
  const SampleIo io(tmp, false);
  std::error_code ec;
  if (path.has_parent_path()) {
    std::filesystem::create_directories(path.parent_path(), ec);
    if (ec) io.fail("cannot create directory '" + path.parent_path().string() + "': " + ec.message());
  }
  try {
    const hid_t file = io.check(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), "cannot create");
    {
      const Handle owner(file, H5Fclose);
      write_file(io, file, p, spec, report);
    }
    std::filesystem::rename(tmp, path, ec);
    if (ec) io.fail("cannot rename to '" + path.string() + "': " + ec.message());
  } catch (...) {
    std::filesystem::remove(tmp, ec);  // best effort: no partial file left behind
    throw;
  }
}

SampleRecord load_sample(const std::filesystem::path& path, ParticleSet& p, double density) {
  const SampleIo io(path, true);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) io.fail("no such file");
  const Handle file(io.check(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "cannot open as HDF5"), H5Fclose);
  if (H5Aexists(file, "format") <= 0 || io.read_string(file, "format") != format_name)
    io.fail("not an arlequin sample (no format attribute '" + std::string(format_name) + "')");
  if (const int version = io.read_scalar<int>(file, "version", H5T_NATIVE_INT); version != format_version)
    io.fail("sample format version " + std::to_string(version) + ", expected " + std::to_string(format_version));

  if (H5Lexists(file, "particles", H5P_DEFAULT) <= 0) io.fail("no group particles");
  const Handle particles(io.check(H5Gopen2(file, "particles", H5P_DEFAULT), "cannot open group particles"), H5Gclose);
  const auto position = io.read_dataset<Vec3>(particles, "position", H5T_NATIVE_DOUBLE, 3);
  const auto radius = io.read_dataset<double>(particles, "radius", H5T_NATIVE_DOUBLE, 1);
  if (radius.size() != position.size()) io.fail("particles/position and radius have different lengths");

  if (H5Lexists(file, "packing", H5P_DEFAULT) <= 0) io.fail("no group packing");
  const Handle packing(io.check(H5Gopen2(file, "packing", H5P_DEFAULT), "cannot open group packing"), H5Gclose);
  SampleRecord record{PackingSpec{decode(io, io.read_string(packing, "region"),
                                         io.read_attribute<double>(packing, "region_numbers", H5T_NATIVE_DOUBLE, 0))},
                      PackingReport{}};
  for (const auto& [name, value] : double_fields(record.spec, record.report))
    *value = io.read_scalar<double>(packing, name, H5T_NATIVE_DOUBLE);
  record.spec.seed = io.read_scalar<std::uint64_t>(packing, "seed", H5T_NATIVE_UINT64);
  record.report.count = io.read_scalar<std::uint64_t>(packing, "count", H5T_NATIVE_UINT64);
  const auto fabric = io.read_attribute<double>(packing, "fabric_eigenvalues", H5T_NATIVE_DOUBLE, 3);
  std::copy(fabric.begin(), fabric.end(), record.report.fabric_eigenvalues.begin());
  const auto centres = io.read_attribute<double>(packing, "radius_histogram_centre", H5T_NATIVE_DOUBLE, 0);
  const auto counts = io.read_attribute<std::uint64_t>(packing, "radius_histogram_count", H5T_NATIVE_UINT64, 0);
  if (centres.size() != counts.size()) io.fail("radius histogram centres and counts have different lengths");
  for (std::size_t k = 0; k < centres.size(); ++k) record.report.radius_histogram.emplace_back(centres[k], counts[k]);

  p.reserve(p.size() + position.size());
  for (std::size_t i = 0; i < position.size(); ++i) p.add(position[i], radius[i], density);
  return record;
}

}  // namespace arlequin::dem
