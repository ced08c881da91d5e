// SPDX-License-Identifier: GPL-3.0-or-later
// Field output for ParaView: heavy data in one HDF5 file, an XDMF 3 index describing a time
// series of frames, each frame a spatial collection of named unstructured grids.
//
// HDF5 layout:  /frames/<6-digit index>/          attribute `time` (double)
//                 <grid>/points                   n x 3 double (absent for grids sharing points)
//                 <grid>/connectivity             m x k int64 (1-D, m entries, for vertex cells)
//                 <grid>/point/<name>, <grid>/cell/<name>
//                                                 n or m (scalars), n x 3 or m x 3 (vectors)
// While the run goes on the HDF5 file is `<h5_path>.part.<pid>`; close() renames it to h5_path.
// The XDMF is rewritten (atomically) after every frame and names the h5 file as it is on disk:
// the .part file until close(), h5_path after. So the frames of a killed run (SIGKILL, a
// second Ctrl-C) open in ParaView as they are, each flushed when it ended.
//
// Serial HDF5 I/O: the file is created with default property lists even when the library
// is the MPI build, and MPI is never initialised here.
#pragma once
#include <cstddef>
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "common/vec3.hpp"

namespace arlequin {

class FieldsWriter {
 public:
  // Nodes per cell: Vertex 1, Line 2, Triangle 3, Tetrahedron 4, Tetrahedron10 10.
  // Tetrahedron10 node order is XDMF's (= VTK_QUADRATIC_TETRA): corners 0-3, then the
  // mid-edge nodes of edges (0,1), (1,2), (0,2), (0,3), (1,3), (2,3). Gmsh orders the last
  // two the other way round ((2,3) then (1,3)): swap nodes 8 and 9 of gmsh tetrahedra.
  enum class CellKind { Vertex, Line, Triangle, Tetrahedron, Tetrahedron10 };

  // Creates `<h5_path>.part` (truncating) and parent directories. Throws RunError.
  FieldsWriter(std::filesystem::path h5_path, std::filesystem::path xdmf_path);
  FieldsWriter(const FieldsWriter&) = delete;
  FieldsWriter& operator=(const FieldsWriter&) = delete;
  // Calls close() unless already closed; errors are reported on stderr.
  ~FieldsWriter();

  // Frames are written one at a time: begin_frame, grids and their fields, end_frame.
  // Calls out of this order, or after close(), throw std::logic_error.
  void begin_frame(double time);
  // Flushes the HDF5 file and rewrites the XDMF so the frame is complete on disk.
  void end_frame();
  // Ends an open frame, closes the HDF5 file, renames it to h5_path, writes the XDMF.
  void close();

  // A grid of the current frame. Grid and field names: non-empty, without '/'. A grid name
  // used twice in a frame, bad connectivity sizes or indices throw std::logic_error; a field
  // name used twice on a grid and centring throws RunError (the dataset already exists).
  // Connectivity holds k point indices per cell, each in [0, points.size()); for Vertex an
  // empty connectivity makes every point a cell.
  void add_grid(const std::string& grid, std::span<const Vec3> points, CellKind kind,
                std::span<const std::int64_t> connectivity);
  // A grid whose points are those of grid `points_of_grid` of this frame: the XDMF refers
  // to the same HDF5 dataset, so the positions are stored once (e.g. bonds between particles).
  void add_grid_sharing_points(const std::string& grid, const std::string& points_of_grid, CellKind kind,
                               std::span<const std::int64_t> connectivity);

  // One value per point / per cell of `grid` (std::logic_error if the size differs).
  void add_point_field(const std::string& grid, const std::string& name, std::span<const double> values);
  void add_point_field(const std::string& grid, const std::string& name, std::span<const Vec3> values);
  void add_point_field(const std::string& grid, const std::string& name, std::span<const std::int32_t> values);
  void add_cell_field(const std::string& grid, const std::string& name, std::span<const double> values);
  void add_cell_field(const std::string& grid, const std::string& name, std::span<const Vec3> values);
  void add_cell_field(const std::string& grid, const std::string& name, std::span<const std::int32_t> values);

  std::size_t frames() const { return frame_count_; }

  // Restart (app/checkpoint.hpp). frames_index() and frame_times(): the XDMF of the first `frames`
  // finished frames with the HDF5 file's name left out, and their times. carry_frames(): copies
  // the first times.size() frames of `earlier` (a file this class wrote) into this writer's file
  // and takes `index` (frames_index() of the writer that wrote them) as their XDMF, so the frames
  // go on from there; only before the first frame. RunError when `earlier` cannot be read, is
  // not tagged with `run` (another run's), lacks one of those frames or has one at another time;
  // then nothing was carried. tag(): the run a file's frames belong to (a root attribute).
  void tag(std::uint64_t run);
  std::string frames_index(std::size_t frames) const;
  std::vector<double> frame_times(std::size_t frames) const {
    return {frame_times_.begin(), frame_times_.begin() + static_cast<std::ptrdiff_t>(std::min(frames, frame_times_.size()))};
  }
  void carry_frames(const std::filesystem::path& earlier, std::uint64_t run, const std::vector<double>& times,
                    const std::string& index);

 private:
  struct Column;  // typed view of values to store (defined in the .cpp)
  struct Grid {
    std::string name;
    std::string geometry;  // XDMF <DataItem> of the positions (possibly another grid's dataset)
    std::size_t points = 0;
    std::size_t cells = 0;
    std::string xml;  // <Grid> content so far: topology, geometry, attributes
  };

  void require_frame(const char* operation) const;
  Grid& grid_named(const std::string& name);
  // Validates a new grid of the open frame and its connectivity; returns the cell count.
  std::size_t check_grid(const std::string& grid, std::size_t points, CellKind kind,
                         std::span<const std::int64_t> connectivity) const;
  // Writes the connectivity and registers the grid in the open frame.
  void add_cells(Grid grid, CellKind kind, std::span<const std::int64_t> connectivity);
  void add_field(const std::string& grid, const std::string& name, bool on_cells, const Column& column);
  // Writes one dataset at `path` (intermediate groups created) and returns the XDMF
  // <DataItem> that reads it. The single place where array data reaches the file.
  std::string write_dataset(const std::string& path, const Column& column) const;
  // Appends the open frame to the XDMF text and closes it (no I/O, so close() can use it).
  void finish_frame();
  void write_xdmf() const;

  std::filesystem::path h5_path_;
  std::filesystem::path part_path_;
  std::filesystem::path xdmf_path_;
  std::string h5_reference_;  // h5 file name as the XDMF refers to it now (relative, XML-escaped)
  std::string reference_to(const std::filesystem::path& h5_file) const;
  std::int64_t file_ = -1;    // HDF5 hid_t; -1 once closed (keeps hdf5.h/mpi.h out of includers)
  bool in_frame_ = false;
  std::size_t frame_count_ = 0;
  double frame_time_ = 0.0;
  std::string frame_path_;    // "/frames/000042"
  std::vector<Grid> grids_;   // grids of the open frame
  std::string frames_xml_;    // finished frames, as XDMF
  std::vector<double> frame_times_;  // of the finished frames
};

}  // namespace arlequin
