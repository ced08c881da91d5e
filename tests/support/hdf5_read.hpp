// SPDX-License-Identifier: GPL-3.0-or-later
// Reading one HDF5 dataset whole in a test: its values as T, in storage order; a dataset that
// cannot be opened or read is a test failure (and gives what could be read). With
// expected_dims, its dimensions are checked too.
#pragma once
#include <gtest/gtest.h>
#include <hdf5.h>

#include <string>
#include <vector>

namespace arlequin::test {

template <class T>
std::vector<T> read_dataset(hid_t file, const std::string& path, hid_t type, const std::vector<hsize_t>* expected_dims = nullptr) {
  std::vector<T> values;
  const hid_t dataset = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  EXPECT_GE(dataset, 0) << path;
  if (dataset < 0) return values;
  const hid_t space = H5Dget_space(dataset);
  if (expected_dims) {
    std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)));
    H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    EXPECT_EQ(dims, *expected_dims) << path;
  }
  values.resize(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
  EXPECT_GE(H5Dread(dataset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0) << path;
  H5Sclose(space);
  H5Dclose(dataset);
  return values;
}

template <class T>
std::vector<T> read_dataset(hid_t file, const std::string& path, hid_t type, const std::vector<hsize_t>& expected_dims) {
  return read_dataset<T>(file, path, type, &expected_dims);
}

}  // namespace arlequin::test
