// SPDX-License-Identifier: GPL-3.0-or-later
// Owner of one HDF5 id, released with its matching close function (H5Fclose, H5Dclose, ...).
// Internal to the .cpp files that talk to HDF5 (hdf5.h pulls in mpi.h: keep it out of headers
// that others include).
#pragma once
#include <hdf5.h>

#include <utility>

namespace arlequin {

class Hdf5Handle {
 public:
  Hdf5Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Hdf5Handle(Hdf5Handle&& other) noexcept : id_(std::exchange(other.id_, -1)), close_(other.close_) {}
  Hdf5Handle(const Hdf5Handle&) = delete;
  Hdf5Handle& operator=(const Hdf5Handle&) = delete;
  Hdf5Handle& operator=(Hdf5Handle&&) = delete;
  ~Hdf5Handle() {
    if (id_ >= 0) close_(id_);
  }
  operator hid_t() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

}  // namespace arlequin
