// SPDX-License-Identifier: GPL-3.0-or-later
// Dense random packings (seed "first challenge", docs/theory.md#packing) and sample files.
#include <gtest/gtest.h>

#include "support/scratch_dir.hpp"
#include <unistd.h>
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

#include "common/error.hpp"
#include "dem/packing.hpp"
#include "dem/sample_file.hpp"
#include "dem/samples.hpp"

namespace arlequin::dem {
namespace {

namespace fs = std::filesystem;

constexpr double mean_radius = 2e-4;  // m: SI-sized, so no tolerance hides in absolute units

// A box of side `radii` mean radii, Gaussian radii with 25 % spread.
PackingSpec box_spec(double radii, std::uint64_t seed) {
  const double side = radii * mean_radius;
  return PackingSpec{Region(Box{{0, 0, 0}, {side, side, side}}), mean_radius, 0.25, 2.0, 0.63, 6.0, seed, 0.03};
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

// The acceptance criteria of a packing, recomputed from the DEs where the report can be
// checked independently.
void expect_dense_isotropic(const ParticleSet& p, const PackingSpec& spec, const PackingReport& report) {
  ASSERT_EQ(report.count, p.size());
  EXPECT_NEAR(report.compaction, 0.63, 0.02);
  EXPECT_GE(report.mean_coordination, 6.0);
  EXPECT_GE(report.interior_coordination, 6.0);
  for (const double eigenvalue : report.fabric_eigenvalues) EXPECT_NEAR(eigenvalue, 1.0 / 3.0, 0.05 / 3.0);
  EXPECT_LT(report.max_overlap, 1e-3);

  // Coordination over all DEs is twice the bonds per DE.
  const auto bonds = close_pairs(p, spec.bond_tolerance);
  EXPECT_DOUBLE_EQ(report.mean_coordination, 2.0 * bonds.size() / p.size());
  // No two spheres overlap by more than 1e-3 mean radii.
  for (const auto& [i, j] : close_pairs(p, 0.0))
    ASSERT_LT(p.radius[i] + p.radius[j] - norm(p.position[j] - p.position[i]), 1e-3 * mean_radius);

  // Radii: within the truncation, mean as asked, histogram of all of them.
  const double half_width = spec.truncation * spec.relative_std * mean_radius;
  double sum = 0.0;
  for (const double r : p.radius) {
    ASSERT_GE(r, mean_radius - half_width);
    ASSERT_LE(r, mean_radius + half_width);
    sum += r;
  }
  EXPECT_NEAR(sum / p.size(), mean_radius, 0.01 * mean_radius);
  std::size_t counted = 0;
  for (const auto& [centre, n] : report.radius_histogram) counted += n;
  EXPECT_EQ(counted, p.size());

  // Ready for bonding: at rest, identity orientation.
  for (std::size_t i = 0; i < p.size(); ++i) {
    ASSERT_EQ(p.orientation[i].w, 1.0);
    ASSERT_EQ(norm2(p.orientation[i].v), 0.0);
    ASSERT_EQ(norm2(p.velocity[i]), 0.0);
  }
}

class SampleFileTest : public test::ScratchDirTest {};

// ~10k DEs, the size of the seed's smaller REV samples; a few seconds.
TEST_F(SampleFileTest, TenThousandDesInABoxAreDenseIsotropicAndSaved) {
  const PackingSpec spec = box_spec(43.0, 11);
  ParticleSet p;
  const PackingReport report = build_packing(p, spec, 1750.0);
  RecordProperty("des", std::to_string(report.count));
  RecordProperty("seconds", std::to_string(report.seconds));
  EXPECT_GT(report.count, 9000u);
  expect_dense_isotropic(p, spec, report);

  // Every sphere inside the box.
  const auto& box = std::get<Box>(spec.region.shape());
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      ASSERT_GE(p.position[i][k] - p.radius[i], box.lower[k] - 1e-3 * mean_radius);
      ASSERT_LE(p.position[i][k] + p.radius[i], box.upper[k] + 1e-3 * mean_radius);
    }
  // Compaction recounted: the share of random points of the inner box (2 mean radii from
  // the walls) that fall in a sphere; 2e5 points, standard error 1.1e-3.
  const double margin = interior_margin * mean_radius, cell = 3.0 * mean_radius;
  const int cells = static_cast<int>((box.upper.x - box.lower.x) / cell) + 1;
  const auto cell_of = [&](double coordinate) {
    return std::clamp(static_cast<int>((coordinate - box.lower.x) / cell), 0, cells - 1);
  };
  std::vector<std::vector<std::size_t>> members(cells * cells * cells);
  for (std::size_t i = 0; i < p.size(); ++i)
    members[(cell_of(p.position[i].z) * cells + cell_of(p.position[i].y)) * cells + cell_of(p.position[i].x)]
        .push_back(i);
  std::mt19937_64 engine(1);
  std::uniform_real_distribution<double> inner(box.lower.x + margin, box.upper.x - margin);
  constexpr int points = 200000;
  int hits = 0;
  for (int n = 0; n < points; ++n) {
    const Vec3 x{inner(engine), inner(engine), inner(engine)};
    bool hit = false;
    for (int cz = std::max(cell_of(x.z) - 1, 0); cz <= std::min(cell_of(x.z) + 1, cells - 1); ++cz)
      for (int cy = std::max(cell_of(x.y) - 1, 0); cy <= std::min(cell_of(x.y) + 1, cells - 1); ++cy)
        for (int cx = std::max(cell_of(x.x) - 1, 0); cx <= std::min(cell_of(x.x) + 1, cells - 1); ++cx)
          for (const std::size_t i : members[(cz * cells + cy) * cells + cx])
            hit = hit || norm2(x - p.position[i]) <= p.radius[i] * p.radius[i];
    hits += hit;
  }
  EXPECT_NEAR(static_cast<double>(hits) / points, report.compaction, 0.005);

  // Save -> load gives the same DEs and the same record, bit for bit.
  const fs::path file = dir_ / "sub" / "sample.h5";
  save_sample(file, p, spec, report);
  EXPECT_FALSE(fs::exists(file.string() + ".tmp." + std::to_string(::getpid())));
  ParticleSet q;
  const SampleRecord record = load_sample(file, q, 1750.0);
  EXPECT_TRUE(same_bits(q.position, p.position));
  EXPECT_TRUE(same_bits(q.radius, p.radius));
  EXPECT_TRUE(same_bits(q.inv_mass, p.inv_mass));
  const auto& loaded_box = std::get<Box>(record.spec.region.shape());
  EXPECT_TRUE(loaded_box.lower == box.lower && loaded_box.upper == box.upper);
  EXPECT_EQ(record.spec.seed, spec.seed);
  EXPECT_EQ(record.spec.mean_radius, spec.mean_radius);
  EXPECT_EQ(record.spec.relative_std, spec.relative_std);
  EXPECT_EQ(record.spec.truncation, spec.truncation);
  EXPECT_EQ(record.spec.target_compaction, spec.target_compaction);
  EXPECT_EQ(record.spec.min_coordination, spec.min_coordination);
  EXPECT_EQ(record.spec.bond_tolerance, spec.bond_tolerance);
  EXPECT_EQ(record.report.count, report.count);
  EXPECT_EQ(record.report.compaction, report.compaction);
  EXPECT_EQ(record.report.mean_coordination, report.mean_coordination);
  EXPECT_EQ(record.report.interior_coordination, report.interior_coordination);
  EXPECT_EQ(record.report.fabric_eigenvalues, report.fabric_eigenvalues);
  EXPECT_EQ(record.report.max_overlap, report.max_overlap);
  EXPECT_EQ(record.report.radius_histogram, report.radius_histogram);
  EXPECT_EQ(record.report.seconds, report.seconds);
}

TEST(Packing, SameSeedSameBitsOtherSeedOtherPacking) {
  ParticleSet a, b, c;
  const PackingReport ra = build_packing(a, box_spec(20.0, 5), 1.0);
  build_packing(b, box_spec(20.0, 5), 1.0);
  build_packing(c, box_spec(20.0, 6), 1.0);
  EXPECT_TRUE(same_bits(a.position, b.position));
  EXPECT_TRUE(same_bits(a.radius, b.radius));
  EXPECT_FALSE(same_bits(a.position, c.position));
  EXPECT_GT(ra.count, 800u);
}

// A tilted cylinder (the fibre of a composite REV): every sphere inside it.
TEST(Packing, CylinderHoldsItsDes) {
  const Vec3 axis = normalized(Vec3{1.0, 1.0, 0.5});
  const Cylinder cylinder{{1e-3, -2e-3, 0.0}, axis, 13.0 * mean_radius, 26.0 * mean_radius};
  const PackingSpec spec{Region(cylinder), mean_radius, 0.25, 2.0, 0.63, 6.0, 3, 0.03};
  ParticleSet p;
  const PackingReport report = build_packing(p, spec, 1200.0);
  EXPECT_GT(report.count, 1500u);
  EXPECT_NEAR(report.compaction, 0.63, 0.02);
  EXPECT_GE(report.interior_coordination, 6.0);
  EXPECT_LT(report.max_overlap, 1e-3);
  const double slack = 1e-3 * mean_radius;
  for (std::size_t i = 0; i < p.size(); ++i) {
    ASSERT_TRUE(spec.region.contains(p.position[i]));
    const Vec3 d = p.position[i] - cylinder.base;
    const double along = dot(d, axis), r = p.radius[i];
    ASSERT_GE(along - r, -slack);
    ASSERT_LE(along + r, cylinder.length + slack);
    ASSERT_LE(norm(d - along * axis) + r, cylinder.radius + slack);
  }
}

TEST(Packing, AppendsAfterExistingDes) {
  ParticleSet p;
  p.add({-1.0, -1.0, -1.0}, 0.1, 1.0);
  const PackingReport report = build_packing(p, box_spec(20.0, 1), 1.0);
  EXPECT_EQ(p.size(), report.count + 1);
  EXPECT_EQ(p.position[0], (Vec3{-1.0, -1.0, -1.0}));
}

TEST(Packing, RejectsBadSpecs) {
  ParticleSet p;
  PackingSpec spec = box_spec(10.0, 1);
  spec.region = Region(HalfSpace{{0, 0, 0}, {0, 0, 1}});
  EXPECT_THROW(build_packing(p, spec, 1.0), std::invalid_argument);
  spec.region = Region(Cylinder{{0, 0, 0}, {0, 0, 1}, 1e-3, -1.0});
  EXPECT_THROW(build_packing(p, spec, 1.0), std::invalid_argument);
  spec = box_spec(10.0, 1);
  spec.relative_std = 0.6;  // x truncation 2: negative radii
  EXPECT_THROW(build_packing(p, spec, 1.0), std::invalid_argument);
  spec = box_spec(10.0, 1);
  spec.bond_tolerance = 0.0;
  EXPECT_THROW(build_packing(p, spec, 1.0), std::invalid_argument);
  EXPECT_EQ(p.size(), 0u);
}

TEST(Packing, TooSmallABondToleranceIsAnError) {
  PackingSpec spec = box_spec(20.0, 1);
  spec.bond_tolerance = 1e-4;
  ParticleSet p;
  try {
    build_packing(p, spec, 1.0);
    FAIL() << "expected a RunError";
  } catch (const RunError& e) {
    EXPECT_NE(std::string(e.what()).find("bond tolerance"), std::string::npos) << e.what();
  }
}

TEST_F(SampleFileTest, BadFilesAreInputErrorsNamingTheFile) {
  ParticleSet p;
  const auto expect_input_error = [&](const fs::path& file, const std::string& reason) {
    try {
      load_sample(file, p, 1.0);
      ADD_FAILURE() << "expected an InputError for " << file;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(file.string()), std::string::npos) << message;
      EXPECT_NE(message.find(reason), std::string::npos) << message;
    }
  };
  expect_input_error(dir_ / "missing.h5", "no such file");
  std::ofstream(dir_ / "text.h5") << "not HDF5\n";
  expect_input_error(dir_ / "text.h5", "HDF5");
  const fs::path other = dir_ / "other.h5";
  H5Fclose(H5Fcreate(other.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT));
  expect_input_error(other, "not an arlequin sample");
  EXPECT_EQ(p.size(), 0u);
}

// 40k DEs, the seed's sample #1 size (Table 2).
TEST(ValidationPacking, FortyThousandDesInABox) {
  const PackingSpec spec = box_spec(68.0, 21);
  ParticleSet p;
  const PackingReport report = build_packing(p, spec, 1750.0);
  RecordProperty("seconds", std::to_string(report.seconds));
  EXPECT_GT(report.count, 38000u);
  expect_dense_isotropic(p, spec, report);
  EXPECT_LT(report.seconds, 300.0);
}

// keep_only (a coupled sample cut to its DEM domain): the kept DEs, in order, with all their
// state; the others gone from every array.
TEST(Samples, KeepOnlyDropsDesAndKeepsTheOthersInOrder) {
  ParticleSet p;
  build_lattice(p, {0, 0, 0}, {6, 1, 1}, 2.0, 1.0, 1000.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.velocity[i] = {double(i), 0, 0};
    p.radius[i] = 1.0 + 0.1 * double(i);
  }
  const std::size_t dropped = p.keep_only([&](std::size_t i) { return i % 2 == 1; });
  EXPECT_EQ(dropped, 3u);
  ASSERT_EQ(p.size(), 3u);
  for (std::size_t k = 0; k < p.size(); ++k) {
    const std::size_t i = 2 * k + 1;
    EXPECT_EQ(p.position[k].x, 2.0 * double(i));
    EXPECT_EQ(p.reference[k].x, 2.0 * double(i));
    EXPECT_EQ(p.velocity[k].x, double(i));
    EXPECT_EQ(p.radius[k], 1.0 + 0.1 * double(i));
  }
  for (std::size_t n : {p.reference.size(), p.velocity.size(), p.orientation.size(), p.angular_velocity.size(),
                        p.force.size(), p.torque.size(), p.radius.size(), p.inv_mass.size()})
    EXPECT_EQ(n, 3u);
}

}  // namespace
}  // namespace arlequin::dem
