// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/state_file.hpp"

#include <hdf5.h>

#include <cstdint>
#include <sstream>
#include <string>
#include <system_error>

#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "common/hdf5_handle.hpp"

namespace arlequin {
namespace {

hid_t memory_type(ElementKind kind) {
  switch (kind) {
    case ElementKind::float64: return H5T_NATIVE_DOUBLE;
    case ElementKind::int64: return H5T_NATIVE_INT64;
    case ElementKind::uint32: return H5T_NATIVE_UINT32;
    case ElementKind::uint8:
    case ElementKind::text: return H5T_NATIVE_UINT8;
  }
  return H5T_NATIVE_UINT8;
}

// FNV-1a, 64 bit: a checksum of the bytes as written, not a cryptographic hash.
struct Fnv1a {
  std::uint64_t value = 14695981039346656037ull;
  void add(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < n; ++k) value = (value ^ p[k]) * 1099511628211ull;
  }
};

std::string index_of(const StateArchive& archive) {
  std::ostringstream index;
  for (const auto& [name, e] : archive.entries())
    index << name << '\t' << static_cast<int>(e.kind) << '\t' << e.width << '\t' << e.rows << '\n';
  return index.str();
}

std::uint64_t checksum(const std::string& index, const StateArchive& archive) {
  Fnv1a sum;
  sum.add(index.data(), index.size());
  for (const auto& [name, e] : archive.entries()) sum.add(e.bytes.data(), e.bytes.size());
  return sum.value;
}

// Writes rows x width elements (1-D when width is 1) at `name`, groups created on the way.
void write_entry(hid_t file, const std::string& name, const StateArchive::Entry& e, const std::filesystem::path& path) {
  const auto fail = [&](const char* what) { throw RunError("HDF5: cannot " + std::string(what) + " '" + name + "' in '" + path.string() + "'"); };
  const hsize_t dims[2] = {e.rows, e.width};
  Hdf5Handle space(H5Screate_simple(e.width > 1 ? 2 : 1, dims, nullptr), H5Sclose);
  Hdf5Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  if (space < 0 || lcpl < 0 || H5Pset_create_intermediate_group(lcpl, 1) < 0) fail("prepare");
  Hdf5Handle set(H5Dcreate2(file, name.c_str(), memory_type(e.kind), space, lcpl, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  if (set < 0) fail("create");
  if (e.rows > 0 && H5Dwrite(set, memory_type(e.kind), H5S_ALL, H5S_ALL, H5P_DEFAULT, e.bytes.data()) < 0) fail("write");
}

}  // namespace

void write_state_file(const std::filesystem::path& path, const StateArchive& archive) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const std::filesystem::path temporary = temporary_path_for(path);
  std::error_code ec;
  try {
    const hid_t file = H5Fcreate(temporary.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file < 0) throw RunError("HDF5: cannot create '" + temporary.string() + "'");
    try {
      const std::string index = index_of(archive);
      StateArchive::Entry index_entry{ElementKind::text, 1, index.size(), {}};
      index_entry.bytes.resize(index.size());
      std::memcpy(index_entry.bytes.data(), index.data(), index.size());
      write_entry(file, "index", index_entry, temporary);
      for (const auto& [name, e] : archive.entries()) write_entry(file, name, e, temporary);
      const std::uint64_t sum = checksum(index, archive);
      Hdf5Handle scalar(H5Screate(H5S_SCALAR), H5Sclose);
      Hdf5Handle attribute(H5Acreate2(file, "checksum", H5T_NATIVE_UINT64, scalar, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
      if (attribute < 0 || H5Awrite(attribute, H5T_NATIVE_UINT64, &sum) < 0)
        throw RunError("HDF5: cannot write the checksum of '" + temporary.string() + "'");
    } catch (...) {
      H5Fclose(file);
      throw;
    }
    // HDF5 writes its buffers at close: a close that fails (a full disk) leaves a file that must
    // not replace the last good checkpoint.
    if (H5Fclose(file) < 0) throw RunError("HDF5: cannot finish writing '" + temporary.string() + "'");
  } catch (...) {
    std::filesystem::remove(temporary, ec);
    throw;
  }
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw RunError("cannot rename '" + temporary.string() + "' to '" + path.string() + "': " + ec.message());
  }
}

StateArchive read_state_file(const std::filesystem::path& path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const auto bad = [&](const std::string& why) { return InputError("'" + path.string() + "': " + why); };
  if (!std::filesystem::is_regular_file(path)) throw bad("no such file");
  if (H5Fis_hdf5(path.c_str()) <= 0) throw bad("not an HDF5 file, or truncated");
  Hdf5Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (file < 0) throw bad("not an HDF5 file, or truncated");
  // Reads the dataset `name` into entry e (its kind, width and rows already set).
  const auto read = [&](const std::string& name, StateArchive::Entry& e) {
    Hdf5Handle set(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose);
    if (set < 0) throw bad("'" + name + "' is missing (truncated or corrupted)");
    Hdf5Handle space(H5Dget_space(set), H5Sclose);
    hsize_t dims[2] = {0, 0};
    const int rank = space < 0 ? -1 : H5Sget_simple_extent_ndims(space);
    if (rank != (e.width > 1 ? 2 : 1) || H5Sget_simple_extent_dims(space, dims, nullptr) != rank || dims[0] != e.rows ||
        (rank == 2 && dims[1] != e.width))
      throw bad("'" + name + "' does not have the shape its index says (corrupted)");
    const std::size_t count = e.rows * e.width;
    e.bytes.resize(e.rows * e.width * element_size(e.kind));
    if (count > 0 && H5Dread(set, memory_type(e.kind), H5S_ALL, H5S_ALL, H5P_DEFAULT, e.bytes.data()) < 0)
      throw bad("'" + name + "' cannot be read (truncated or corrupted)");
  };
  Hdf5Handle index_set(H5Dopen2(file, "index", H5P_DEFAULT), H5Dclose);
  if (index_set < 0) throw bad("no /index: not an arlequin checkpoint");
  Hdf5Handle index_space(H5Dget_space(index_set), H5Sclose);
  const hssize_t index_size = index_space < 0 ? -1 : H5Sget_simple_extent_npoints(index_space);
  if (index_size < 0) throw bad("/index cannot be read (corrupted)");
  StateArchive::Entry index_entry{ElementKind::text, 1, static_cast<std::size_t>(index_size), {}};
  read("index", index_entry);
  const std::string index(reinterpret_cast<const char*>(index_entry.bytes.data()), index_entry.bytes.size());

  StateArchive archive;
  std::istringstream lines(index);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream fields(line);
    std::string name;
    int kind = -1;
    StateArchive::Entry e;
    if (!std::getline(fields, name, '\t') || !(fields >> kind >> e.width >> e.rows) || kind < 0 ||
        kind > static_cast<int>(ElementKind::text) || e.width == 0)
      throw bad("/index line '" + line + "' is not 'name kind width rows' (corrupted)");
    e.kind = static_cast<ElementKind>(kind);
    // Sizes a file of ours cannot hold (what rows x width x element size would overflow).
    if (e.rows > (std::size_t{1} << 40) / e.width) throw bad("/index line '" + line + "' gives an impossible size (corrupted)");
    read(name, e);
    archive.put_entry(name, std::move(e));
  }
  std::uint64_t stored = 0;
  Hdf5Handle attribute(H5Aopen(file, "checksum", H5P_DEFAULT), H5Aclose);
  if (attribute < 0 || H5Aread(attribute, H5T_NATIVE_UINT64, &stored) < 0) throw bad("no checksum (truncated or corrupted)");
  if (stored != checksum(index, archive)) throw bad("its checksum does not match its contents (corrupted)");
  return archive;
}

}  // namespace arlequin
