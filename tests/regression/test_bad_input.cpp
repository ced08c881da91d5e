// SPDX-License-Identifier: GPL-3.0-or-later
// Bad input gets a clear one-line error naming the file, line and key, a non-zero exit and
// no crash. Each case edits one line of a valid case file (or the command line).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <vector>

#include "app/scene.hpp"
#include "support/cli.hpp"

namespace arlequin {
namespace {

const std::vector<std::string> valid_case = {
    "name: bad_input",                                                             // 1
    "time: {end: 1.0e-4, dt: auto}",                                               // 2
    "dem:",                                                                        // 3
    "  density: 7800",                                                             // 4
    "  sample: {build: chain, count: 3, radius: 1.0e-3}",                          // 5
    "  bond: {law: beam, E_mu: 2.0e11, r_mu: 0.5}",                                // 6
    "groups:",                                                                     // 7
    "  - {name: left, region: {box: [[-1, -1, -1], [0.0005, 1, 1]]}}",             // 8
    "  - {name: right, region: {half_space: {point: [0.003, 0, 0], normal: [1, 0, 0]}}}",  // 9
    "boundary:",                                                                   // 10
    "  - {group: left, type: fixed}",                                              // 11
    "  - {group: right, type: velocity, value: [0.1, 0, 0]}",                      // 12
    "sensors:",                                                                    // 13
    "  - {name: F, type: force, group: right, component: x}",                      // 14
    "output: {every: 1.0e-5}",                                                     // 15
};

struct BadInput {
  std::string name;
  int line;                 // line of valid_case to replace (1-based), 0: none
  std::string replacement;  // new text of that line
  std::string extra_args;   // appended to the command line
  std::vector<std::string> expected;  // substrings of the error line
  // A second line to replace (0: none), given by the cases that need it only.
  int line2 = 0;
  std::string replacement2 = "";
};

std::ostream& operator<<(std::ostream& os, const BadInput& b) { return os << b.name; }

// Lines 6-7 of a case whose chain is two materials (DEs 0 and 1 in `a`, the box, DE 2 in `b`)
// joined by a cohesive interface with these parameters; line 4 (one density) becomes no_density.
std::string cohesive_interface(const std::string& parameters, const std::string& box = "[[-1, -1, -1], [0.003, 1, 1]]") {
  // Appended piece by piece: GCC 12 warns falsely of overlapping copies in "..." + s + "...".
  std::string lines = "  materials: {a: {density: 7800, region: {box: ";
  lines += box;
  lines += "}, bond: {law: beam, E_mu: 2.0e11, r_mu: 0.5}}, b: {density: 7800, bond: {law: beam, E_mu: 2.0e11, r_mu: 0.5}}}\n"
           "  interface: {bond: {law: cohesive_bilinear, ";
  lines += parameters;
  lines += "}}";
  return lines;
}
const std::string no_density = "  # density: per material";

class BadInputTest : public ::testing::TestWithParam<BadInput> {};

TEST_P(BadInputTest, OneLineErrorNamingWhereAndNonZeroExit) {
  const BadInput& b = GetParam();
  const auto dir = test::scratch_dir("bad_" + b.name);
  const auto file = dir / "case.yaml";
  {
    std::ofstream out(file);
    for (std::size_t k = 0; k < valid_case.size(); ++k)
      out << (int(k) + 1 == b.line ? b.replacement : int(k) + 1 == b.line2 ? b.replacement2 : valid_case[k]) << "\n";
  }
  const auto r = test::run_arlequin("check " + file.string() + " " + b.extra_args);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_EQ(r.output.rfind("arlequin: error: ", 0), 0u) << r.output;
  for (const auto& s : b.expected) EXPECT_NE(r.output.find(s), std::string::npos) << "missing '" << s << "' in: " << r.output;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadInputTest,
    ::testing::Values(
        BadInput{"unknown_top_key", 15, "outptu: {every: 1.0e-5}", "", {"case.yaml:15", "outptu", "did you mean 'output'"}},
        BadInput{"unknown_nested_key", 6, "  bond: {law: beam, E_mu: 2.0e11, r_mu: 0.5, tolerence: 0.01}", "",
                 {"case.yaml:6", "dem.bond.tolerence", "did you mean 'tolerance'"}},
        BadInput{"wrong_type", 2, "time: {end: abc}", "", {"case.yaml:2", "time.end", "expected a number"}},
        BadInput{"negative_radius", 5, "  sample: {build: chain, count: 3, radius: -1.0e-3}", "",
                 {"case.yaml:5", "dem.sample.radius", "> 0"}},
        BadInput{"unit_suffix", 5, "  sample: {build: chain, count: 3, radius: 1 mm}", "",
                 {"case.yaml:5", "dem.sample.radius", "no unit suffix"}},
        BadInput{"dt_above_critical", 2, "time: {end: 1.0e-4, dt: 1.0e-3}", "",
                 {"case.yaml:2", "time.dt", "critical time step"}},
        BadInput{"empty_group", 9, "  - {name: right, region: {box: [[5, 5, 5], [6, 6, 6]]}}", "",
                 {"case.yaml:9", "region", "contains no DE"}},
        BadInput{"contradictory_boundary", 9, "  - {name: right, region: {box: [[-1, -1, -1], [1, 1, 1]]}}", "",
                 {"case.yaml:", "boundary", "only one boundary condition"}},
        BadInput{"unknown_bond_law", 6, "  bond: {law: bem, E_mu: 2.0e11, r_mu: 0.5}", "",
                 {"case.yaml:6", "dem.bond.law", "did you mean 'beam'"}},
        BadInput{"yaml_syntax", 5, "  sample: {build: chain, count: 3, radius: [1.0e-3}", "",
                 {"case.yaml:", "YAML syntax error"}},
        BadInput{"unknown_group", 11, "  - {group: lefft, type: fixed}", "",
                 {"case.yaml:11", "boundary[0].group", "unknown group 'lefft'"}},
        BadInput{"fractional_count", 5, "  sample: {build: chain, count: 2.5, radius: 1.0e-3}", "",
                 {"case.yaml:5", "dem.sample.count"}},
        BadInput{"missing_required", 2, "time: {dt: auto}", "", {"case.yaml:2", "time", "missing required key 'end'"}},
        BadInput{"r_mu_out_of_range", 6, "  bond: {law: beam, E_mu: 2.0e11, r_mu: 5}", "",
                 {"case.yaml:6", "dem.bond.r_mu"}},
        BadInput{"unknown_crack_bond_set", 14, "  - {name: a, type: crack, bonds: interfce}", "",
                 {"case.yaml:14", "sensors[0].bonds", "no bond set named 'interfce'"}},
        BadInput{"unknown_sensor_type", 14, "  - {name: F, type: forse, group: right}", "",
                 {"case.yaml:14", "sensors[0].type", "did you mean 'force'"}},
        BadInput{"rdef_compaction_with_laguerre_volumes", 6,
                 "  bond: {law: beam, E_mu: 2.0e11, r_mu: 0.5}\n  failure: {rdef: {threshold: 1.0e8, volume: laguerre, compaction: 0.6}}", "",
                 {"case.yaml", "compaction", "only for volume: sphere"}},
        BadInput{"affine_deviation_without_initial_strain", 14, "  - {name: d, type: affine_deviation}", "",
                 {"case.yaml:14", "sensors[0].type", "needs an initial_strain section"}},
        BadInput{"unknown_output_field", 15, "output: {fields: [particle]}", "",
                 {"case.yaml:15", "output.fields", "particle"}},
        BadInput{"duplicate_group", 9, "  - {name: left, region: {box: [[-1, -1, -1], [1, 1, 1]]}}", "",
                 {"case.yaml:9", "groups[1].name", "defined twice"}},
        BadInput{"inverted_box", 8, "  - {name: left, region: {box: [[1, 1, 1], [0, 0, 0]]}}", "",
                 {"case.yaml:8", "box", "lower corner"}},
        BadInput{"ramp_missing", 12, "  - {group: right, type: displacement, value: [1.0e-6, 0, 0]}", "",
                 {"case.yaml:12", "boundary[1]", "missing required key 'ramp'"}},
        BadInput{"negative_density", 4, "  density: -7800", "", {"case.yaml:4", "dem.density"}},
        BadInput{"duplicate_yaml_key", 4, "  density: 7800\n  density: 1000", "", {"case.yaml:", "density", "duplicate key"}},
        BadInput{"stiffness_overflow", 6, "  bond: {law: beam, E_mu: 1.0e308, r_mu: 0.5}", "",
                 {"case.yaml:1", "critical time step is 0 s", "out of range"}},
        BadInput{"too_many_steps", 6, "  bond: {law: beam, E_mu: 1.0e300, r_mu: 0.5}", "",
                 {"case.yaml:2", "time.end", "more than 1e15"}},
        BadInput{"end_below_one_step", 2, "time: {end: 1.0e-300, dt: auto}", "",
                 {"case.yaml:2", "time.end", "no step would run"}},
        BadInput{"misspelt_required_key", 6, "  bond: {law: beam, E_m: 2.0e11, r_mu: 0.5}", "",
                 {"case.yaml:6", "missing required key 'E_mu'", "is 'E_m' (line 6) a misspelling of 'E_mu'?"}},
        BadInput{"cohesive_strength_not_positive", 6, cohesive_interface("sigma_max: -5.7e6, G_I: 560, stiffness: 1.0e15"), "",
                 {"case.yaml:7", "dem.interface.bond.sigma_max", "> 0"}, 4, no_density},
        BadInput{"cohesive_toughness_not_positive", 6, cohesive_interface("sigma_max: 5.7e6, G_I: 0, stiffness: 1.0e15"), "",
                 {"case.yaml:7", "dem.interface.bond.G_I", "> 0"}, 4, no_density},
        BadInput{"cohesive_u_p_below_elastic_opening", 6, cohesive_interface("sigma_max: 5.7e6, G_I: 560, stiffness: 1.0e4"), "",
                 {"case.yaml:7", "dem.interface.bond.G_I", "not beyond the elastic opening"}, 4, no_density},
        BadInput{"cohesive_interface_crossed_by_no_pair", 6,
                 cohesive_interface("sigma_max: 5.7e6, G_I: 560, stiffness: 1.0e15", "[[-1, -1, -1], [1, 1, 1]]"), "",
                 {"case.yaml:", "dem.interface.bond.law", "no pair of DEs"}, 4, no_density},
        BadInput{"cohesive_precrack_longer_than_specimen", 6,
                 cohesive_interface("sigma_max: 5.7e6, G_I: 560, stiffness: 1.0e15, precrack: {box: [[-1, -1, -1], [1, 1, 1]]}"), "",
                 {"case.yaml:", "dem.interface.bond.precrack", "as long as the specimen"}, 4, no_density},
        // A sensor column named like a built-in one or another sensor's: series.csv got two
        // columns of one name and a check judged the first.
        BadInput{"sensor_named_like_a_builtin_column", 14, "  - {name: E_total, type: force, group: right, component: x}", "",
                 {"case.yaml:14", "sensors[0].name", "column 'E_total'"}},
        BadInput{"sensor_named_time", 14, "  - {name: time, type: force, group: right, component: x}", "",
                 {"case.yaml:14", "sensors[0].name", "column 'time'"}},
        BadInput{"sensor_column_of_another_sensor", 14,
                 "  - {name: F, type: force, group: right}\n  - {name: F_y, type: force, group: right, component: y}", "",
                 {"case.yaml:15", "sensors[1].name", "column 'F_y'"}},
        // The name is the output folder's last component: no way out of results/, no NUL.
        BadInput{"name_leaving_results", 1, "name: ../../..", "", {"case.yaml:1", "name", "results/<name>"}},
        BadInput{"name_with_a_nul", 1, "name: \"a\\0b\"", "", {"case.yaml:1", "name", "results/<name>"}},
        // Far beyond this machine's memory: refused before anything is built (it ended in
        // std::bad_alloc, exit 4).
        BadInput{"lattice_beyond_memory", 5, "  sample: {build: lattice, counts: [2000, 2000, 2000], radius: 1.0e-3}", "",
                 {"case.yaml:5", "dem.sample.counts", "8e+09 DEs", "this machine has"}},
        BadInput{"chain_beyond_memory", 5, "  sample: {build: chain, count: 1000000000000, radius: 1.0e-3}", "",
                 {"case.yaml:5", "dem.sample.count", "1e+12 DEs", "this machine has"}},
        BadInput{"packing_beyond_memory", 5,
                 "  sample: {build: packing, region: {box: [[0, 0, 0], [1, 1, 1]]}, radius: {mean: 1.0e-5}}", "",
                 {"case.yaml:5", "dem.sample.region", "1.41e+14 DEs", "this machine has"}},
        BadInput{"malformed_override", 0, "", "--set time.end", {"--set time.end"}},
        BadInput{"override_out_of_range", 0, "", "--set time.safety=2", {"--set time.safety=2", "time.safety"}},
        BadInput{"unknown_option", 0, "", "--stpes 3", {"unknown option '--stpes'"}}),
    [](const auto& param_info) { return param_info.param.name; });

TEST(BadInput, MissingCaseFile) {
  const auto r = test::run_arlequin("run /nonexistent/folder/case.yaml");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("/nonexistent/folder/case.yaml"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("cannot open"), std::string::npos) << r.output;
}

TEST(BadInput, UnknownCommandSuggestsTheClosest) {
  const auto r = test::run_arlequin("rnu x.yaml");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("did you mean 'run'"), std::string::npos) << r.output;
}

// A mesh gmsh cannot read (a syntax error in a .geo, a truncated .msh) is an input error naming
// the file (and the .geo's line), not an uncaught exception (it was: exit 134, no file named).
TEST(BadInput, MalformedMeshIsAOneLineErrorNamingTheFile) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const auto dir = test::scratch_dir("bad_mesh");
  std::ofstream(dir / "syntax.geo") << "Point(1) = {0, 0, 0;\n";
  std::ofstream(dir / "truncated.msh") << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 8 1 8\n3 1 0 8\n1\n2\n";
  const std::string bar = std::string(ARLEQUIN_SOURCE_DIR) + "/cases/bar_wave_continuum/case.yaml";
  for (const std::string file : {"syntax.geo", "truncated.msh"}) {
    const std::string path = (dir / file).string();
    const auto r = test::run_arlequin("check " + bar + " --set continuum.mesh.file=" + path);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_EQ(r.output.rfind("arlequin: error: ", 0), 0u) << r.output;
    EXPECT_NE(r.output.find("continuum.mesh.file"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(path), std::string::npos) << r.output;
  }
  const auto r = test::run_arlequin("check " + bar + " --set continuum.mesh.file=" + (dir / "syntax.geo").string());
  EXPECT_NE(r.output.find("line 1"), std::string::npos) << r.output;
}

// Every input the fuzz targets (fuzz/, scripts/fuzz.sh) crashed on, kept in
// data/fuzz_found/<reader>/: `check` now refuses it in one line naming the file, or accepts it.
// mesh/: .msh files gmsh's reader crashed on (gmsh_double_free.msh: a mutated MSH 4.1 whose
// entities made it free a block twice), refused after gmsh, in a process of its own, crashes on
// them (continuum/mesh.cpp); and files arlequin's own reading crashed on
// (surface_on_unused_node.msh: a surface group's triangle on a node no tetrahedron uses threw
// std::out_of_range), refused naming the group and the node. particle_table/: tables of fuzz/fuzz_particle_table.cpp's
// case (large_de_bonded_to_all.csv: DEs of 10 m among DEs of 1 mm, bonded to all of them, ended
// in "internal error: bond colouring: more than 64 colours"; now coloured, then refused for its
// coincident DEs; de_far_beyond_the_others.csv: a DE 2e34 m from the rest overflowed the
// contact grid's cell count, undefined behaviour; now binned in cells grown to fit, and accepted).
TEST(BadInput, EveryInputTheFuzzersCrashedOnIsRefusedInOneLine) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const std::filesystem::path found = std::string(ARLEQUIN_SOURCE_DIR) + "/tests/regression/data/fuzz_found";
  const std::string bar = std::string(ARLEQUIN_SOURCE_DIR) + "/cases/bar_wave_continuum/case.yaml";
  int inputs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(found / "mesh")) {
    ++inputs;
    const std::string path = entry.path().string();
    const auto r = test::run_arlequin("check " + bar + " --set continuum.mesh.file=" + path);
    EXPECT_EQ(r.exit_code, 2) << path << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    const bool gmsh_crash = entry.path().filename().string().starts_with("gmsh_");
    EXPECT_NE(r.output.find(path + (gmsh_crash ? ": gmsh crashes reading it" : ": physical group")), std::string::npos) << r.output;
  }
  const auto dir = test::scratch_dir("fuzz_found_tables");
  std::ofstream(dir / "case.yaml") << "name: fuzz_table\ntime: {end: 1.0e-6}\ndem:\n  density: 7800\n"
                                      "  sample: {build: particles, table: table.csv}\n"
                                      "  bond: {law: beam, E_mu: 2.0e11, r_mu: 0.5}\n"
                                      "  contact: {law: penalty, stiffness: 1.0e7}\n";
  for (const auto& entry : std::filesystem::directory_iterator(found / "particle_table")) {
    ++inputs;
    std::filesystem::copy_file(entry.path(), dir / "table.csv", std::filesystem::copy_options::overwrite_existing);
    const auto r = test::run_arlequin("check " + (dir / "case.yaml").string());
    EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 2) << entry.path() << ": " << r.output;
    if (r.exit_code == 2) {
      EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    }
    EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  }
  EXPECT_GE(inputs, 2);
}

// A large set of DEs comes as a CSV table (a YAML list of 500 000 DEs took the YAML parser
// minutes in check): it is read as written, and a bad row is an error at FILE:LINE.
TEST(BadInput, ParticleTableIsReadAndItsBadRowsNamed) {
  const auto dir = test::scratch_dir("particle_table");
  const auto write_case = [&](const std::string& table) {
    std::ofstream(dir / "des.csv") << table;
    std::ofstream(dir / "case.yaml") << "name: table\ntime: {end: 1.0e-6, dt: 1.0e-8}\ndem:\n  density: 7800\n"
                                        "  sample: {build: particles, table: des.csv}\n";
    return test::run_arlequin("check " + (dir / "case.yaml").string(), "stdout");
  };
  const auto good = write_case("x,y,z,radius,vx,vy,vz\n0,0,0,0.001,1.5,0,0\n0.002,0,0,0.001,0,0,-2\n\n0.004,0,0,0.002,0,0,0\n");
  ASSERT_EQ(good.exit_code, 0) << good.output;
  EXPECT_NE(good.output.find("DEs: 3"), std::string::npos) << good.output;
  const app::Scene scene = app::build_scene((dir / "case.yaml").string(), {.overrides = {}, .out_dir = dir / "out", .petsc_options = ""});
  const dem::ParticleSet& p = scene.dem.particles;
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p.position[1].x, 0.002);
  EXPECT_EQ(p.radius[2], 0.002);
  EXPECT_EQ(p.velocity[0].x, 1.5);
  EXPECT_EQ(p.velocity[1].z, -2.0);
  struct Bad {
    std::string table, expected;
  };
  for (const Bad& b : std::vector<Bad>{{"x,y,z,r\n0,0,0,1\n", "des.csv:1: expected the header x,y,z,radius"},
                                       {"x,y,z,radius\n0,0,0,0.001\n0,0,zero,0.001\n", "des.csv:3: expected 4 comma-separated numbers"},
                                       {"x,y,z,radius\n0,0,0,0.001,7\n", "des.csv:2: expected 4 comma-separated numbers"},
                                       {"x,y,z,radius\n0,0,0,-0.001\n", "des.csv:2: a radius must be > 0 m"},
                                       {"x,y,z,radius\n", "des.csv: no DE in the table"}}) {
    const auto r = write_case(b.table);
    EXPECT_EQ(r.exit_code, 2) << b.table;
    const auto err = test::run_arlequin("check " + (dir / "case.yaml").string());
    EXPECT_NE(err.output.find(b.expected), std::string::npos) << "missing '" << b.expected << "' in: " << err.output;
    EXPECT_EQ(std::count(err.output.begin(), err.output.end(), '\n'), 1) << err.output;
  }
}

// A mesh size far below the body's extent is refused before meshing (it ran for hours, silent).
TEST(BadInput, MeshBeyondMemoryIsRefusedBeforeMeshing) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const auto r = test::run_arlequin("check " + std::string(ARLEQUIN_SOURCE_DIR) +
                                    "/cases/bar_wave_continuum/case.yaml --set continuum.mesh.size=1e-5");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  for (const char* s : {"continuum.mesh", "size 1e-05 m", "1e+13 nodes", "this machine has"})
    EXPECT_NE(r.output.find(s), std::string::npos) << "missing '" << s << "' in: " << r.output;
}

// The continuum's PETSc options are checked before the run, as the coupling's are: an option
// PETSc refuses or leaves unread, or options given to a continuum that solves nothing (explicit),
// is a one-line error (they were ignored, or failed the run with PETSc's trace).
TEST(BadInput, ContinuumPetscOptionsAreChecked) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const std::string cases = std::string(ARLEQUIN_SOURCE_DIR) + "/cases/";
  const std::string static_case = "check " + cases + "cantilever_continuum/case.yaml --petsc ";
  struct Refusal {
    std::string command;
    std::vector<std::string> expected;
  };
  for (const Refusal& r : std::vector<Refusal>{
           {static_case + "\"-ksp_type bogus\"", {"continuum.petsc_options", "PETSc refused", "-ksp_type bogus"}},
           {static_case + "\"-nonexistent_option 1\"", {"continuum.petsc_options", "did not use '-nonexistent_option 1'"}},
           {"check " + cases + "bar_wave_continuum/case.yaml --petsc \"-ksp_type cg\"", {"--petsc", "static", "explicit"}}}) {
    const auto out = test::run_arlequin(r.command);
    EXPECT_EQ(out.exit_code, 2) << out.output;
    EXPECT_EQ(std::count(out.output.begin(), out.output.end(), '\n'), 1) << out.output;
    for (const auto& s : r.expected) EXPECT_NE(out.output.find(s), std::string::npos) << "missing '" << s << "' in: " << out.output;
  }
  EXPECT_EQ(test::run_arlequin(static_case + "\"-ksp_type gmres -ksp_monitor_cancel\"").exit_code, 0);
}

}  // namespace
}  // namespace arlequin
