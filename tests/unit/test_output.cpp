// SPDX-License-Identifier: GPL-3.0-or-later
// Output writers: atomic files, CSV series, JSON summaries and HDF5/XDMF fields.
#include <gtest/gtest.h>

#include "support/hdf5_read.hpp"
#include "support/scratch_dir.hpp"
#include <unistd.h>
#include <hdf5.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "common/atomic_file.hpp"
#include "common/csv_series.hpp"
#include "common/error.hpp"
#include "common/fields_writer.hpp"
#include "common/json.hpp"

namespace arlequin {
namespace {

namespace fs = std::filesystem;

class OutputTest : public test::ScratchDirTest {};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

TEST_F(OutputTest, AtomicWriteReplacesContentAndLeavesNoTemporary) {
  const fs::path path = dir_ / "sub" / "file.txt";
  write_file_atomically(path, "first version, rather long\n");
  write_file_atomically(path, "second\n");
  EXPECT_EQ(read_text(path), "second\n");
  EXPECT_EQ(temporary_path_for(path), dir_ / "sub" / ("file.txt.tmp." + std::to_string(::getpid())));
  EXPECT_FALSE(fs::exists(temporary_path_for(path)));
  EXPECT_THROW(write_file_atomically(path / "below_a_file", "x"), RunError);
}

// What a killed writer left (<name>.tmp.<pid>, <name>.part.<pid> of a process that is gone) is
// removed; a live process's temporaries and every other file stay.
TEST_F(OutputTest, StaleTemporariesOfDeadWritersAreRemoved) {
  const std::string own = std::to_string(::getpid()), gone = "999999999";  // above any pid_max
  const std::vector<std::string> kept = {"series.csv.tmp." + own, "fields.h5.part." + own, "notes.txt", "a.tmp.12x",
                                         "fields.h5"};
  for (const std::string& name : kept) write_file_atomically(dir_ / name, "x");
  write_file_atomically(dir_ / ("series.csv.tmp." + gone), "x");
  write_file_atomically(dir_ / ("fields.h5.part." + gone), "x");
  EXPECT_EQ(remove_stale_temporaries(dir_), 2u);
  EXPECT_FALSE(fs::exists(dir_ / ("series.csv.tmp." + gone)));
  EXPECT_FALSE(fs::exists(dir_ / ("fields.h5.part." + gone)));
  for (const std::string& name : kept) EXPECT_TRUE(fs::exists(dir_ / name)) << name;
}

TEST_F(OutputTest, CsvSeriesRoundTrip) {
  const fs::path path = dir_ / "series.csv";
  {
    CsvSeries series(path, {"time", "energy", "count"});
    const double first[] = {0.0, 1.0 / 3.0, 7.0};
    const double second[] = {1e-3, -123456.789012345, 1e300};
    series.append(first);
    series.append(second);
    const double wrong[] = {1.0, 2.0};
    EXPECT_THROW(series.append(wrong), std::logic_error);
    ASSERT_EQ(series.rows(), 2u);
    EXPECT_EQ(series.row(1)[1], -123456.789012345);
    EXPECT_EQ(series.columns().size(), 3u);
    series.flush();
    EXPECT_EQ(read_text(path), "time,energy,count\n0,0.333333333333,7\n0.001,-123456.789012,1e+300\n");
    const double third[] = {2e-3, 0.5, 8.0};
    series.append(third);
  }  // the destructor writes the last row
  EXPECT_EQ(read_text(path),
            "time,energy,count\n0,0.333333333333,7\n0.001,-123456.789012,1e+300\n0.002,0.5,8\n");
  EXPECT_FALSE(fs::exists(temporary_path_for(path)));
}

// Our contract over nlohmann-json: summaries keep their keys in insertion order, non-finite
// numbers become null, the file is replaced atomically, and a file that is not JSON is an
// InputError naming it.
// A string that is not UTF-8 (a byte 0xff from a folder or a sensor name) still gives a JSON
// file: the bad byte becomes U+FFFD (it made summary.json invalid, or the dump threw).
TEST_F(OutputTest, JsonFileIsValidWithAStringThatIsNotUtf8) {
  Json summary = Json::object();
  summary["name"] = std::string("case\xff" "1");
  const fs::path path = dir_ / "summary.json";
  write_json_atomically(path, summary);
  EXPECT_EQ(read_json_file(path).at("name").get<std::string>(), "case\xef\xbf\xbd" "1");
}

TEST_F(OutputTest, JsonFilesKeepOrderWriteNullForNonFiniteAndNameABadFile) {
  Json summary = Json::object();
  summary["steps"] = std::size_t{1000};
  summary["name"] = "a";
  summary["ratio"] = 0.1;
  summary["nan"] = std::nan("");
  summary["inf"] = std::numeric_limits<double>::infinity();
  const fs::path path = dir_ / "summary.json";
  write_json_atomically(path, summary);
  const std::string text = read_text(path);
  EXPECT_LT(text.find("\"steps\""), text.find("\"name\""));
  EXPECT_NE(text.find("\"nan\": null"), std::string::npos) << text;
  EXPECT_NE(text.find("\"inf\": null"), std::string::npos) << text;
  EXPECT_FALSE(fs::exists(temporary_path_for(path)));
  const Json back = read_json_file(path);
  EXPECT_EQ(back.at("steps").get<std::int64_t>(), 1000);
  EXPECT_EQ(back.at("ratio").get<double>(), 0.1);
  EXPECT_TRUE(back.at("nan").is_null());

  write_file_atomically(dir_ / "bad.json", "{\"a\": 1,");
  try {
    read_json_file(dir_ / "bad.json");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json: not a JSON document"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_json_file(dir_ / "missing.json"), InputError);
}

using test::read_dataset;

double read_time(hid_t file, const std::string& frame) {
  double time = -1.0;
  const hid_t attribute = H5Aopen_by_name(file, frame.c_str(), "time", H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(attribute, 0) << frame;
  EXPECT_GE(H5Aread(attribute, H5T_NATIVE_DOUBLE, &time), 0);
  H5Aclose(attribute);
  return time;
}

TEST_F(OutputTest, FieldsWriterParticlesAndBonds) {
  const fs::path h5 = dir_ / "out" / "fields.h5";
  const fs::path xdmf = dir_ / "out" / "fields.xdmf";
  const std::vector<std::int64_t> bonds = {0, 1, 1, 2};
  const double times[] = {0.0, 0.25};
  {
    FieldsWriter writer(h5, xdmf);
    for (int f = 0; f < 2; ++f) {
      const std::vector<Vec3> positions = {{0, 0, 0}, {1.0 + f, 0, 0}, {0, 2, 0.5 * f}};
      const std::vector<double> radius = {0.1, 0.2, 0.3 + f};
      const std::vector<Vec3> velocity = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9.0 + f}};
      const std::vector<std::int32_t> id = {10, 11, 12 + f};
      const std::vector<double> force = {1.5, -2.5 * f};
      writer.begin_frame(times[f]);
      writer.add_grid("particles", positions, FieldsWriter::CellKind::Vertex, {});
      writer.add_point_field("particles", "radius", std::span<const double>(radius));
      writer.add_point_field("particles", "velocity", std::span<const Vec3>(velocity));
      writer.add_point_field("particles", "id", std::span<const std::int32_t>(id));
      writer.add_grid_sharing_points("bonds", "particles", FieldsWriter::CellKind::Line, bonds);
      writer.add_cell_field("bonds", "force", std::span<const double>(force));
      EXPECT_THROW(writer.add_cell_field("bonds", "bad", std::span<const double>(radius)), std::logic_error);
      EXPECT_THROW(writer.add_grid("bonds", positions, FieldsWriter::CellKind::Line, bonds), std::logic_error);
      const std::vector<std::int64_t> out_of_range = {0, 3};
      EXPECT_THROW(writer.add_grid("broken", positions, FieldsWriter::CellKind::Line, out_of_range), std::logic_error);
      writer.end_frame();
      EXPECT_TRUE(fs::exists(fs::path(h5) += ".part." + std::to_string(::getpid())));
      // While the run goes on the index names the file on disk, so a killed run's frames open.
      const std::string part_reference = "fields.h5.part." + std::to_string(::getpid()) + ":/frames/";
      EXPECT_NE(read_text(xdmf).find(part_reference), std::string::npos);
      EXPECT_EQ(read_text(xdmf).find("fields.h5:"), std::string::npos);
    }
    EXPECT_THROW(writer.add_grid("late", {}, FieldsWriter::CellKind::Vertex, {}), std::logic_error);
    EXPECT_EQ(writer.frames(), 2u);
    writer.close();
  }
  EXPECT_FALSE(fs::exists(fs::path(h5) += ".part." + std::to_string(::getpid())));
  ASSERT_TRUE(fs::exists(h5));
  EXPECT_EQ(read_text(xdmf).find(".part."), std::string::npos);

  const hid_t file = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  for (int f = 0; f < 2; ++f) {
    const std::string frame = f == 0 ? "/frames/000000" : "/frames/000001";
    EXPECT_EQ(read_time(file, frame), times[f]);
    const auto points = read_dataset<double>(file, frame + "/particles/points", H5T_NATIVE_DOUBLE, {3, 3});
    EXPECT_EQ(points, (std::vector<double>{0, 0, 0, 1.0 + f, 0, 0, 0, 2, 0.5 * f}));
    EXPECT_EQ(read_dataset<std::int64_t>(file, frame + "/particles/connectivity", H5T_NATIVE_INT64, {3}),
              (std::vector<std::int64_t>{0, 1, 2}));
    EXPECT_EQ(read_dataset<double>(file, frame + "/particles/point/radius", H5T_NATIVE_DOUBLE, {3}),
              (std::vector<double>{0.1, 0.2, 0.3 + f}));
    EXPECT_EQ(read_dataset<double>(file, frame + "/particles/point/velocity", H5T_NATIVE_DOUBLE, {3, 3}),
              (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9.0 + f}));
    EXPECT_EQ(read_dataset<std::int32_t>(file, frame + "/particles/point/id", H5T_NATIVE_INT32, {3}),
              (std::vector<std::int32_t>{10, 11, 12 + f}));
    EXPECT_EQ(read_dataset<std::int64_t>(file, frame + "/bonds/connectivity", H5T_NATIVE_INT64, {2, 2}), bonds);
    EXPECT_EQ(read_dataset<double>(file, frame + "/bonds/cell/force", H5T_NATIVE_DOUBLE, {2}),
              (std::vector<double>{1.5, -2.5 * f}));
    EXPECT_EQ(H5Lexists(file, (frame + "/bonds/points").c_str(), H5P_DEFAULT), 0);  // positions stored once
  }

  const std::string text = read_text(xdmf);
  EXPECT_NE(text.find("Version=\"3.0\""), std::string::npos);
  EXPECT_NE(text.find("CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_NE(text.find("<Grid Name=\"particles\""), std::string::npos);
  EXPECT_NE(text.find("<Grid Name=\"bonds\""), std::string::npos);
  EXPECT_NE(text.find("<Time Value=\"0\"/>"), std::string::npos);
  EXPECT_NE(text.find("<Time Value=\"0.25\"/>"), std::string::npos);
  EXPECT_NE(text.find("TopologyType=\"Polyline\""), std::string::npos);
  // Every dataset the XDMF refers to exists in the final file.
  const std::string prefix = "fields.h5:";
  std::size_t references = 0;
  for (std::size_t at = text.find(prefix); at != std::string::npos; at = text.find(prefix, at + 1)) {
    const std::size_t start = at + prefix.size();
    const std::string path = text.substr(start, text.find('<', start) - start);
    EXPECT_GT(H5Oexists_by_name(file, path.c_str(), H5P_DEFAULT), 0) << path;
    ++references;
  }
  // Per frame: particles points + connectivity + 3 fields, bonds shared points + connectivity + 1 field.
  EXPECT_EQ(references, 2u * 8u);
  EXPECT_EQ(H5Fclose(file), 0);
}

}  // namespace
}  // namespace arlequin
