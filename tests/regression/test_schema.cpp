// SPDX-License-Identifier: GPL-3.0-or-later
// The case-file schema (app/case_schema.cpp) against its readers: every key a reader asks for is
// declared with the type, unit, range, choices and default it is read with (CaseNode checks
// each read; a mismatch is a logic error, so any case or test that reads the key finds it),
// and every declared key is read by some reader (below: the shipped cases and variants that
// take the readers through their other branches).
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "app/calibrate.hpp"
#include "app/case_schema.hpp"
#include "app/virtual_tests.hpp"
#include "app/scene.hpp"
#include "common/error.hpp"
#include "support/cli.hpp"
#include "support/scratch_dir.hpp"

namespace arlequin {
namespace {

using SchemaTest = test::ScratchDirTest;

const std::string cases = std::string(ARLEQUIN_SOURCE_DIR) + "/cases/";

// Builds the scene of `file` with `overrides`. Input errors are expected of some variants: a
// reader asks for its keys before it judges them, so the keys count as read all the same.
void read_case(const std::string& file, std::vector<Override> overrides, const std::filesystem::path& dir) {
  app::SceneOptions options;
  options.overrides = std::move(overrides);
  options.out_dir = dir / "out";
  options.check_output_dir = false;
  try {
    app::build_scene(file, options);
  } catch (const InputError&) {
  }
}

// The names of the keys `schema` declares that no read has asked for ("section: key" lines).
std::string unread_keys(const Schema& schema) {
  std::string unread;
  for (const SchemaSection& section : schema.sections())
    for (const KeyDoc& key : section.keys)
      if (!schema.read().contains(std::string(section.path) + "|" + std::string(key.key)))
        unread += "\n  " + std::string(section.path) + ": " + std::string(key.key);
  return unread;
}

TEST_F(SchemaTest, EveryDeclaredKeyIsReadByItsReader) {
  // A small packing for the REVs (their cached samples hold 10k DEs).
  const std::vector<Override> small_packing = {"dem.sample.radius.mean=1.2e-4", "dem.sample.file=" + (dir_ / "sample.h5").string()};
  for (const char* c : {"bar_wave_continuum/case.yaml", "bonded_block_tension/case.yaml", "cantilever_chain/case.yaml",
                        "cantilever_continuum/case.yaml", "demo_beam_impact/case.yaml", "lattice_bar_failure/case.yaml",
                        "patch_coupled/case.yaml", "patch_coupled/free_surface.yaml", "wave_bar_coupled/case.yaml",
                        "wave_bar_coupled/above_cutoff.yaml", "wave_bar_dem/case.yaml"})
    read_case(cases + c, {}, dir_);
  for (const char* c : {"rev_elastic/case.yaml", "rev_elastic/homogeneous.yaml"}) read_case(cases + c, small_packing, dir_);

  // The other branches of the readers.
  const std::string chain = cases + "cantilever_chain/case.yaml", bar = cases + "bar_wave_continuum/case.yaml",
                    coupled = cases + "wave_bar_coupled/case.yaml", rev = cases + "rev_elastic/case.yaml";
  std::vector<Override> rdef = small_packing;
  rdef.insert(rdef.end(), {"dem.failure={rdef: {threshold: 1.0e8}}"});
  read_case(rev, rdef, dir_);
  rdef.back() = "dem.failure={rdef: {material_thresholds: {fibre: 5.0e9, matrix: 1.5e8}}}";
  read_case(rev, rdef, dir_);
  read_case(chain, {"dem.bond={law: spring, stiffness: 1.0e6, max_elongation: 0.1}", "dem.contact={law: penalty, stiffness: 1.0e6}",
                    "initial=[{group: tip, velocity: [0, 0, 1], angular_velocity: [0, 0, 1]}]",
                    "sensors=[{name: e, type: energy, group: tip}]"},
            dir_);
  read_case(chain, {"groups=[{name: a, ids: [0, 1]}, {name: b, region: {sphere: {center: [0, 0, 0], radius: 1}}}, "
                    "{name: c, region: {half_space: {point: [0, 0, 0], normal: [1, 0, 0]}}}, "
                    "{name: d, region: {cylinder: {base: [0, 0, 0], axis: [1, 0, 0], radius: 1, length: 1}}}]",
                    "boundary=[{group: a, type: displacement, value: [0, 0, 1.0e-6], ramp: 0.1, rotation: fixed}]"},
            dir_);
  read_case(chain, {"pulse={group: tip, direction: [1, 0, 0], center: [0, 0, 0], wavelength: 1.0e-3, amplitude: 0.1, speed: 1000, cycles: 3}",
                    "checks=[{column: tip_deflection, crossing: 1.0e-6, expected: 0.1, tolerance: 0.1}, "
                    "{column: tip_deflection, at_most: 1, at_least: 0}]",
                    "initial_strain={gradient: [[1.0e-3, 0, 0], [0, 0, 0], [0, 0, 0]]}"},
            dir_);
  read_case(bar, {"continuum.material={model: transversely_isotropic, E_L: 1.0e11, E_T: 1.0e10, nu_LT: 0.3, nu_TT: 0.4, G_LT: 5.0e9, "
                  "axis: [1, 0, 0], density: 1500}",
                  "continuum.boundary=[{group: xmin, type: traction, value: [1, 0, 0]}]"},
            dir_);
  read_case(bar, {"continuum.material={model: orthotropic, E_x: 7.0e9, E_y: 5.0e9, E_z: 5.0e6, G_xy: 4.0e6, G_xz: 3.0e6, "
                  "G_yz: 2.0e6, nu_xy: 0.01, nu_xz: 0.02, nu_yz: 0.03, density: 338}"},
            dir_);
  read_case(cases + "dcb/case.yaml",
            {"dem.sample.radius.mean=4.0e-4", "dem.sample.file=" + (dir_ / "dcb_sample.h5").string(),
             "groups=[{name: load_top, region: {box: [[-1, -1, 0.0015], [5.0e-4, 1, 1]]}}, "
             "{name: load_bottom, region: {box: [[-1, -1, -1], [5.0e-4, 1, 0.0015]]}}]",
             "dem.interface.bond.sigma_max_shear=8.0e6", "dem.interface.bond.G_II=900", "dem.interface.bond.bk_exponent=1.5",
             "dem.contact={law: penalty, stiffness: 5.0e7, friction: 0.3, slip_velocity: 1.0e-3}",
             "sensors=[{name: P, type: force, group: load_top, component: z}, {name: Delta, type: displacement, group: load_top, "
             "component: z}, {name: t, type: crack, bonds: interface, quantity: tip, axis: [1, 0, 0], across: [0, 1, 0], bins: 4}]"},
            dir_);
  read_case(coupled, {"coupling.type=h1", "coupling.length=1.0e-3", "coupling.weight=constant", "coupling.solver=direct"}, dir_);
  read_case(coupled, {"coupling.overlap={shell: {inner: [[0, 0, 0], [1, 1, 1]], outer: [[-1, -1, -1], [2, 2, 2]]}}"}, dir_);
  read_case(coupled, {"coupling.overlap={shells: [{inner: [[0, 0, 0], [1, 1, 1]], outer: [[-1, -1, -1], [2, 2, 2]]}, "
                      "{inner: [[0, 0, 0], [3, 0.5, 1]], outer: [[-1, -1, -1], [4, 1, 2]]}]}"},
            dir_);
  read_case(cases + "dcb_coupled/case.yaml",  // its band overlap, on the DCB's packing above
            {"dem.sample.radius.mean=4.0e-4", "dem.sample.file=" + (dir_ / "dcb_sample.h5").string(),
             "continuum.mesh.file=../../meshes/dcb_arms_coarse.geo", "coupling.overlap.band.half_thickness=1.0e-3",
             "coupling.overlap.band.width=5.0e-4", "coupling.overlap.band.to=0.027",
             "dem.interface.bond.area=0.9e-4", "continuum.mesh.join={box: [[0.026875, -1, -1], [1, 1, 1]]}",
             // a band that follows the crack is not checkpointed
             "coupling.overlap.band.follow={margin: 4.0e-3, ahead: 8.0e-3, behind: 1.5e-3, until: 0.046}",
             "output={every: 1.0e-5, fields: []}"},
            dir_);

  read_case(cases + "fabric_impact/reduced.yaml",
            {"dem.sample.crimp=0.7", "dem.sample.yarn.section=2.0e-7", "dem.contact.stiffness=1.0e7", "dem.gravity=[0, 0, -9.81]"}, dir_);
  read_case(cases + "yarn_wave/case.yaml", {}, dir_);
  read_case(cases + "fabric_impact_coupled/reduced.yaml", {}, dir_);  // its ties

  std::ofstream(dir_ / "des.csv") << "x,y,z,radius\n0,0,0,0.001\n0.002,0,0,0.001\n";
  std::ofstream(dir_ / "table.yaml") << "time: {end: 1.0e-6, dt: 1.0e-8}\ndem:\n  density: 7800\n"
                                        "  sample: {build: particles, table: des.csv}\n";
  read_case((dir_ / "table.yaml").string(), {}, dir_);

  EXPECT_TRUE(unread_keys(app::case_schema()).empty()) << "declared but never read:" << unread_keys(app::case_schema());
}

// The same for the spec files of `arlequin virtual-test` and `arlequin calibrate`: the shipped
// specs, and one of each that takes the readers through their other branches (read only: no
// test or calibration runs).
TEST_F(SchemaTest, EveryDeclaredSpecKeyIsReadByItsReader) {
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  };
  const std::string rev_case = cases + "rev_elastic/case.yaml";
  for (const char* spec : {"rev_elastic/virtual_tests.yaml", "rev_failure/failure_tests.yaml"}) app::validate_virtual_test_spec(cases + spec);
  app::validate_virtual_test_spec(write("elastic.yaml", "case: " + rev_case + "\n"
      "samples: [{name: a, set: [dem.sample.seed=8]}]\n"
      "quasi_static: {strain: 1.0e-4, ramp: 2, plateau: 2, damping: 0.4, average: 0.4, rows_per_transit: 10}\n"
      "composite:\n  fibre: {E: 2.6e11, nu: 0.3}\n  matrix: {E: 3.45e9, nu: 0.35}\n  fibre_fraction: 0.5\n"
      "  references: [{name: r, E_L: 1.0e11, E_T: 1.0e10, nu_LT: 0.3, nu_TT: 0.4, G_LT: 5.0e9, G_TT: 3.0e9}]\n"
      "tests:\n  - {name: L, tension: z, modulus_estimate: 1.0e11}\n  - {name: T, tension: x}\n"
      "  - {name: LT, shear: [x, z]}\n  - {name: TT, shear: [x, y]}\n"));
  const Schema& suite = app::virtual_test_schema();
  EXPECT_TRUE(unread_keys(suite).empty()) << "declared but never read:" << unread_keys(suite);

  for (const char* spec : {"rev_elastic/calibration.yaml", "rev_failure/calibration.yaml", "rev_failure/calibration_laguerre.yaml"})
    app::CalibrationSpec::read(cases + spec);
  app::CalibrationSpec::read(write("calibration.yaml", "case: " + rev_case + "\nbond: dem.materials.matrix.bond\n"
      "r_mu: [0.2, 0.3]\naxes: [x, z]\ntolerance: 0.01\nverify: [{name: v, set: [dem.sample.seed=8]}]\n"
      "quasi_static: {strain: 1.0e-4}\n"
      "targets: [{name: epoxy, E: 3.45e9, nu: 0.35, reference: {E_mu: 1.0e11, r_mu: 0.3}}]\n"
      "failure: {axis: z, tolerance: 0.05, test: {transits: 10},\n"
      "  targets: [{name: epoxy, criterion: rdef, stress: 7.0e7, initial: 1.0e8, variant: v, set: [dem.failure.rdef.average=none]},\n"
      "            {name: other, criterion: bbf, stress: 7.0e7, E: 3.0e9, E_mu: 1.0e11, r_mu: 0.3, reference: 2.0e9}]}\n"));
  const Schema& calibration = app::calibration_schema();
  EXPECT_TRUE(unread_keys(calibration).empty()) << "declared but never read:" << unread_keys(calibration);
}

// `arlequin schema` prints every section from the one table; a section on request; an unknown
// one is refused with a suggestion.
TEST(Schema, TheCommandPrintsTheDeclaredSections) {
  const auto all = test::run_arlequin("schema", "stdout");
  ASSERT_EQ(all.exit_code, 0) << all.output;
  for (const SchemaSection& section : app::case_schema().sections())
    EXPECT_NE(all.output.find(std::string(section.path) + ": " + std::string(section.help) + "\n"), std::string::npos) << section.path;
  EXPECT_NE(all.output.find("bond (law: beam): "), std::string::npos);
  EXPECT_NE(all.output.find("  E_mu                number > 0 [Pa]"), std::string::npos) << all.output;
  const auto sample = test::run_arlequin("schema dem.sample", "stdout");
  ASSERT_EQ(sample.exit_code, 0);
  EXPECT_NE(sample.output.find("dem.sample.radius: "), std::string::npos);
  EXPECT_EQ(sample.output.find("dem: "), std::string::npos) << sample.output;
  EXPECT_EQ(sample.output.find("time: "), std::string::npos) << sample.output;
  const auto unknown = test::run_arlequin("schema dem.smaple");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.output.find("no section 'dem.smaple'; did you mean 'dem.sample'?"), std::string::npos) << unknown.output;
}

}  // namespace
}  // namespace arlequin
