// SPDX-License-Identifier: GPL-3.0-or-later
// Material regions: DEs take their region's material (density, group) and bonds get the set of
// their materials, or the interface set across materials.
#include <gtest/gtest.h>

#include <numbers>

#include "app/scene.hpp"
#include "common/error.hpp"
#include "support/cli.hpp"

namespace arlequin {
namespace {

const std::string data = std::string(ARLEQUIN_SOURCE_DIR) + "/tests/regression/data/";

TEST(Materials, RegionsAssignDensityGroupsAndBondSets) {
  app::Scene scene = app::build_scene(data + "two_materials.yaml", {});
  const auto& model = scene.dem;
  // Lattice points (2 mm apart) within 5 mm of the axis: offsets 1 and 3 mm in x and y,
  // 16 columns of 10 DEs.
  const int fibre = model.group_index("fibre"), matrix = model.group_index("matrix");
  ASSERT_GE(fibre, 0);
  ASSERT_GE(matrix, 0);
  EXPECT_EQ(model.members(fibre).size(), 160u);
  EXPECT_EQ(model.members(matrix).size(), 840u);
  // In-material bonds: fibre 16 x 9 along z + 24 per layer in x-y; interface bonds cross the
  // cylinder's boundary (16 per layer).
  ASSERT_EQ(model.bond_sets().size(), 3u);
  EXPECT_EQ(model.bond_sets()[0]->name, "fibre");
  EXPECT_EQ(model.bond_sets()[0]->size(), 16u * 9u + 24u * 10u);
  EXPECT_EQ(model.bond_sets()[2]->name, "interface");
  EXPECT_EQ(model.bond_sets()[2]->size(), 160u);
  EXPECT_EQ(model.bond_sets()[0]->size() + model.bond_sets()[1]->size() + model.bond_sets()[2]->size(),
            3u * 10u * 10u * 9u);
  const double volume = 4.0 / 3.0 * std::numbers::pi * 1e-9;
  EXPECT_NEAR(model.particles.mass(model.members(fibre)[0]), 1750.0 * volume, 1e-12 * 1750.0 * volume);
  EXPECT_NEAR(model.particles.mass(model.members(matrix)[0]), 1200.0 * volume, 1e-12 * 1200.0 * volume);
}

TEST(Materials, ASecondMaterialWithoutRegionIsRefused) {
  const auto dir = test::scratch_dir("materials_two_rest");
  std::string text = test::read_text(data + "two_materials.yaml");
  // Drop the fibre's region: fibre and matrix would both take "the rest".
  const auto at = text.find("fibre: {region: {cylinder: {base: [0.009, 0.009, 0], axis: [0, 0, 1], radius: 0.005}}, ");
  ASSERT_NE(at, std::string::npos);
  text.erase(at + std::string("fibre: {").size(), std::string("region: {cylinder: {base: [0.009, 0.009, 0], axis: [0, 0, 1], radius: 0.005}}, ").size());
  std::ofstream(dir / "case.yaml") << text;
  const auto r = test::run_arlequin("check " + (dir / "case.yaml").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("only one material may go without a region"), std::string::npos) << r.output;
}

// RDEF thresholds per material: every material named once, or a default threshold for the rest.
TEST(Materials, RdefThresholdsPerMaterial) {
  const auto build = [](const std::string& rdef) {
    app::SceneOptions options;
    options.overrides = {"dem.failure.rdef=" + rdef};
    return app::build_scene(data + "two_materials.yaml", options);
  };
  EXPECT_TRUE(build("{material_thresholds: {fibre: 5.0e9, matrix: 1.5e8}}").dem.failure_enabled());
  EXPECT_NO_THROW(build("{threshold: 1.0e8, material_thresholds: {fibre: 5.0e9}}"));
  const auto error = [&](const std::string& rdef) {
    try {
      build(rdef);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("{material_thresholds: {fiber: 5.0e9, matrix: 1.5e8}}").find("fiber: no material of that name"), std::string::npos);
  EXPECT_NE(error("{material_thresholds: {fibre: 5.0e9}}").find("without their own: matrix"), std::string::npos);
  EXPECT_NE(error("{threshold: 1.0e8, material_thresholds: {fibre: 5.0e9, matrix: 1.5e8}}").find("every material has its own"),
            std::string::npos);
}

}  // namespace
}  // namespace arlequin

namespace arlequin {
namespace {

// initial_strain puts every DE on u = H x (bonds keep their unstrained reference): a lattice
// held on that field at both ends is in exact equilibrium and must not move.
TEST(InitialStrain, AHeldUniformStrainIsAnExactStaticState) {
  const auto out = test::scratch_dir("dem_patch");
  const auto r = test::run_arlequin("run " + data + "dem_patch.yaml --quiet --out " + out.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;  // the case's checks: no motion, u = eps x
}

}  // namespace
}  // namespace arlequin
