// SPDX-License-Identifier: GPL-3.0-or-later
// Case-file reading: typed values, defaults, resolved output, overrides and the one-line
// error messages (location, key path, what was expected).
#include "common/case_file.hpp"

#include <gtest/gtest.h>

#include "support/scratch_dir.hpp"
#include <yaml-cpp/yaml.h>

#include <array>
#include <fstream>
#include <functional>
#include <unistd.h>

#include "common/error.hpp"
#include "common/schema.hpp"

namespace arlequin {
namespace {

namespace fs = std::filesystem;

class CaseFileTest : public test::ScratchDirTest {
 protected:
  fs::path write(const std::string& text, const std::string& name = "case.yaml") {
    const fs::path file = dir_ / name;
    fs::create_directories(file.parent_path());
    std::ofstream(file) << text;
    return file;
  }
  CaseFile load(const std::string& text, const std::vector<Override>& overrides = {}) {
    return CaseFile::load(write(text), overrides);
  }
};

// The message of the InputError thrown by `f` ("" if none was thrown).
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text)

constexpr std::array<std::string_view, 3> kElements{"beam", "shell", "solid"};

const char* const kCase = R"(time:
  end: 1e-3
  steps: 200
dem:
  sample:
    radius: 0.001
    density: 2500
  gravity: [0, 0, -9.81]
  periodic: true
  element: shell
  name: glass beads
output:
  fields: [velocity, stress]
  every: auto
)";

TEST_F(CaseFileTest, ReadsTypedValuesAndDefaults) {
  CaseFile c = load(kCase);
  CaseNode root = c.root();
  CaseNode time = root.child("time");
  EXPECT_DOUBLE_EQ(time.number("end", Range::positive(), "s"), 1e-3);
  EXPECT_EQ(time.integer("steps", Range::at_least(1)), 200);
  EXPECT_DOUBLE_EQ(time.number_or("dt", 1e-6, Range::positive(), "s"), 1e-6);
  EXPECT_EQ(time.integer_or("threads", 4, Range::at_least(1)), 4);
  time.finish();

  CaseNode dem = root.child("dem");
  CaseNode sample = dem.child("sample");
  EXPECT_DOUBLE_EQ(sample.number("radius", Range::positive(), "m"), 0.001);
  EXPECT_DOUBLE_EQ(sample.number("density", Range::positive(), "kg/m^3"), 2500);
  sample.finish();
  const Vec3 g = dem.vec3("gravity", Range::any(), "m/s^2");
  EXPECT_EQ(g, (Vec3{0, 0, -9.81}));
  EXPECT_EQ(dem.vec3_or("origin", Vec3{1, 2, 3}, Range::any(), "m"), (Vec3{1, 2, 3}));
  EXPECT_TRUE(dem.boolean("periodic"));
  EXPECT_FALSE(dem.boolean_or("restart", false));
  EXPECT_EQ(dem.choice("element", kElements), "shell");
  EXPECT_EQ(dem.choice_or("solver", "beam", kElements), "beam");
  EXPECT_EQ(dem.string("name"), "glass beads");
  EXPECT_EQ(dem.string_or("label", "none"), "none");
  EXPECT_FALSE(dem.has("contacts"));
  EXPECT_FALSE(dem.child_if("contacts").has_value());
  dem.finish();

  CaseNode output = root.child("output");
  EXPECT_EQ(output.strings("fields"), (std::vector<std::string>{"velocity", "stress"}));
  EXPECT_EQ(output.strings_or("groups", {"all"}), (std::vector<std::string>{"all"}));
  EXPECT_FALSE(output.number_or_auto("every", Range::positive(), "s").has_value());
  EXPECT_FALSE(output.number_or_auto("interval", Range::positive(), "s").has_value());
  output.finish();
  root.finish();
  EXPECT_EQ(root.keys(), (std::vector<std::string>{"time", "dem", "output"}));
}

TEST_F(CaseFileTest, ResolvedYamlHasReadValuesAndDefaultsInReadOrder) {
  CaseFile c = load(kCase);
  CaseNode root = c.root();
  CaseNode dem = root.child("dem");
  dem.child("sample").number("radius", Range::positive(), "m");
  dem.number_or("damping", 0.05, Range::between(0, 1), "1");
  dem.vec3("gravity", Range::any(), "m/s^2");
  root.child("time").number("end", Range::positive(), "s");
  root.child("output").strings_or("groups", {"all", "true"});

  const std::string text = c.resolved_yaml();
  EXPECT_CONTAINS(text, "damping: 0.05");
  EXPECT_CONTAINS(text, "gravity: [0, 0, -9.81]");
  EXPECT_CONTAINS(text, "\"true\"");  // a string that would read back as a bool is quoted
  EXPECT_EQ(text.find("density"), std::string::npos) << text;  // never read
  EXPECT_LT(text.find("dem:"), text.find("time:")) << text;

  const YAML::Node back = YAML::Load(text);
  EXPECT_DOUBLE_EQ(back["dem"]["sample"]["radius"].as<double>(), 0.001);
  EXPECT_DOUBLE_EQ(back["time"]["end"].as<double>(), 1e-3);
  EXPECT_EQ(back["output"]["groups"][1].as<std::string>(), "true");
}

TEST_F(CaseFileTest, UnknownKeySuggestsClosestWithLine) {
  CaseFile c = load("dem:\n  radius: 1\n  sampel:\n    radius: 1\n");
  CaseNode dem = c.root().child("dem");
  dem.number("radius", Range::positive(), "m");
  dem.child_if("sample");
  EXPECT_CONTAINS(error_of([&] { dem.finish(); }),
                  "case.yaml:3: dem.sampel: unknown key; did you mean 'sample'?");
}

TEST_F(CaseFileTest, UnknownKeyFarFromAllListsValidKeys) {
  CaseFile c = load("time:\n  end: 1\n  zzzzzzzz: 2\n");
  CaseNode time = c.root().child("time");
  time.number("end", Range::positive(), "s");
  time.number_or("dt", 1, Range::positive(), "s");
  EXPECT_CONTAINS(error_of([&] { time.finish(); }),
                  "case.yaml:3: time.zzzzzzzz: unknown key; valid keys: end, dt");
}

TEST_F(CaseFileTest, WrongTypeRangeUnitSuffixAndNonInteger) {
  CaseFile c = load("s:\n  a: abc\n  b: -0.001\n  c: 1 mm\n  d: 2.5\n  e: [1, 2]\n  f: yes\n  g: [1, x, 3]\n");
  CaseNode s = c.root().child("s");
  EXPECT_CONTAINS(error_of([&] { s.number("a", Range::positive(), "m"); }),
                  "case.yaml:2: s.a: expected a number > 0 [m], got 'abc'");
  EXPECT_CONTAINS(error_of([&] { s.number("b", Range::positive(), "m"); }),
                  "case.yaml:3: s.b: expected a number > 0 [m], got -0.001");
  EXPECT_CONTAINS(error_of([&] { s.number("c", Range::positive(), "m"); }),
                  "case.yaml:4: s.c: expected a number > 0 [m] (SI units, no unit suffix), got '1 mm'");
  EXPECT_CONTAINS(error_of([&] { s.integer("d", Range::at_least(1)); }),
                  "case.yaml:5: s.d: expected an integer >= 1, got 2.5");
  EXPECT_CONTAINS(error_of([&] { s.number("e", Range::between(0, 1), "1"); }),
                  "s.e: expected a number in [0, 1], got a list of 2 items");
  EXPECT_CONTAINS(error_of([&] { s.vec3("e", Range::any(), "m"); }),
                  "s.e: expected a list of 3 numbers [m], got a list of 2 items");
  EXPECT_CONTAINS(error_of([&] { s.boolean("f"); }), "s.f: expected true or false, got 'yes'");
  EXPECT_CONTAINS(error_of([&] { s.numbers("g", Range::any(), "Pa"); }),
                  "case.yaml:8: s.g[1]: expected a number [Pa], got 'x'");
  EXPECT_CONTAINS(error_of([&] { s.child("a"); }), "s.a: expected a mapping, got 'abc'");
  EXPECT_CONTAINS(error_of([&] { s.string("e"); }), "s.e: expected a string, got a list of 2 items");
  EXPECT_CONTAINS(error_of([&] { s.number_or_auto("a", Range::positive(), "s"); }),
                  "expected a number > 0 [s] or 'auto', got 'abc'");
}

TEST_F(CaseFileTest, IntegerOrAutoReadsAWholeNumberTheWordAutoOrTheFallback) {
  CaseFile c = load("s:\n  a: 3\n  b: auto\n  c: 2.5\n  d: many\n");
  CaseNode s = c.root().child("s");
  const Range range = Range::between(1, 1000);
  EXPECT_EQ(s.integer_or_auto("a", 1, range), std::optional<long long>(3));
  EXPECT_FALSE(s.integer_or_auto("b", 1, range).has_value());
  EXPECT_EQ(s.integer_or_auto("missing", 7, range), std::optional<long long>(7));
  EXPECT_CONTAINS(error_of([&] { s.integer_or_auto("c", 1, range); }), "case.yaml:4: s.c: expected an integer in [1, 1000], got 2.5");
  EXPECT_CONTAINS(error_of([&] { s.integer_or_auto("d", 1, range); }),
                  "case.yaml:5: s.d: expected an integer in [1, 1000] or 'auto', got 'many'");
}

TEST_F(CaseFileTest, BadChoiceSuggestsClosest) {
  CaseFile c = load("dem:\n  element: bem\n");
  CaseNode dem = c.root().child("dem");
  EXPECT_CONTAINS(error_of([&] { dem.choice("element", kElements); }),
                  "case.yaml:2: dem.element: expected one of beam, shell, solid, got 'bem'; did you mean 'beam'?");
}

TEST_F(CaseFileTest, MissingRequiredKeyNamesParentAndKey) {
  CaseFile c = load("dem:\n  sample:\n    density: 1\n");
  CaseNode sample = c.root().child("dem").child("sample");
  EXPECT_CONTAINS(error_of([&] { sample.number("radius", Range::positive(), "m"); }),
                  "case.yaml:2: dem.sample: missing required key 'radius' (a number > 0 [m])");
  EXPECT_CONTAINS(error_of([&] { c.root().child("time"); }), "case.yaml:1: missing required key 'time'");
}

TEST_F(CaseFileTest, MissingRequiredKeyPointsAtItsMisspelling) {
  CaseFile c = load("bond:\n  E_m: 1e9\n  r_mu: 0.3\n");
  CaseNode bond = c.root().child("bond");
  bond.number("r_mu", Range::positive(), "1");
  EXPECT_CONTAINS(error_of([&] { bond.number("E_mu", Range::positive(), "Pa"); }),
                  "case.yaml:1: bond: missing required key 'E_mu' (a number > 0 [Pa]); is 'E_m' (line 2) a "
                  "misspelling of 'E_mu'?");
  // A valid key not read yet is no misspelling, even one substitution away (E_mu simply forgotten).
  CaseFile forgotten = load("bond:\n  r_mu: 0.3\n  nu_mu: 0.2\n");
  CaseNode bond2 = forgotten.root().child("bond");
  const std::string message = error_of([&] { bond2.number("E_mu", Range::positive(), "Pa"); });
  EXPECT_CONTAINS(message, "missing required key 'E_mu'");
  EXPECT_EQ(message.find("misspelling"), std::string::npos) << message;
  CaseFile swapped = load("group:\n  regoin: {box: 1}\n");
  EXPECT_CONTAINS(error_of([&] { swapped.root().child("group").child("region"); }), "is 'regoin' (line 2) a misspelling of 'region'?");
}

TEST_F(CaseFileTest, MissingFile) {
  EXPECT_CONTAINS(error_of([&] { CaseFile::load(dir_ / "nope.yaml"); }),
                  "nope.yaml: cannot open case file (No such file or directory)");
}

TEST_F(CaseFileTest, YamlSyntaxErrorHasLine) {
  const std::string message = error_of([&] { load("a: 1\nb: [1, 2\nc: 3\n"); });
  EXPECT_CONTAINS(message, "case.yaml:");
  EXPECT_CONTAINS(message, ": YAML syntax error: ");
  EXPECT_EQ(message.find("yaml-cpp: error at"), std::string::npos) << message;
  EXPECT_CONTAINS(error_of([&] { load("a: {b: 1}\nc:\n  d: 1\n   e: 2\n"); }), "case.yaml:4: YAML syntax error:");
}

TEST_F(CaseFileTest, DuplicateAndTopLevelKindAreErrors) {
  EXPECT_CONTAINS(error_of([&] { load("a: 1\nb: 2\na: 3\n").root(); }),
                  "case.yaml:3: a: duplicate key (first given at line 1)");
  EXPECT_CONTAINS(error_of([&] { load("- 1\n- 2\n"); }),
                  "case.yaml:1: expected a mapping of sections at the top level, got a list of 2 items");
}

TEST_F(CaseFileTest, OverridesReplaceAndCreateValues) {
  CaseFile c = load(kCase, {"time.end=2e-3", "output.fields=[a, b, c]", "dem.contact.stiffness=1e6",
                            "time.steps = 10"});
  CaseNode root = c.root();
  CaseNode time = root.child("time");
  EXPECT_DOUBLE_EQ(time.number("end", Range::positive(), "s"), 2e-3);
  EXPECT_EQ(time.integer("steps", Range::at_least(1)), 10);
  EXPECT_EQ(root.child("output").strings("fields"), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_DOUBLE_EQ(root.child("dem").child("contact").number("stiffness", Range::positive(), "N/m"), 1e6);
}

TEST_F(CaseFileTest, MalformedOverridesAreNamed) {
  const fs::path file = write(kCase);
  EXPECT_CONTAINS(error_of([&] { CaseFile::load(file, {"time.end"}); }),
                  "--set time.end: expected key.path=value");
  EXPECT_CONTAINS(error_of([&] { CaseFile::load(file, {"=3"}); }), "--set =3: empty key");
  EXPECT_CONTAINS(error_of([&] { CaseFile::load(file, {"time..end=3"}); }), "--set time..end=3: empty key");
  EXPECT_CONTAINS(error_of([&] { CaseFile::load(file, {"time.end.x=3"}); }),
                  "--set time.end.x=3: 'time.end' is 1e-3, not a mapping");
  EXPECT_CONTAINS(error_of([&] { CaseFile::load(file, {"time.end=[1"}); }),
                  "--set time.end=[1: YAML syntax error in value");
}

TEST_F(CaseFileTest, OverriddenValuesReportTheOverride) {
  CaseFile c = load(kCase, {"dem.sample.radius=-1", "dem.extra.sampel=2"});
  CaseNode dem = c.root().child("dem");
  EXPECT_CONTAINS(error_of([&] { dem.child("sample").number("radius", Range::positive(), "m"); }),
                  "--set dem.sample.radius=-1: dem.sample.radius: expected a number > 0 [m], got -1");
  CaseNode extra = dem.child("extra");
  extra.number_or("sample", 1, Range::any(), "1");
  EXPECT_CONTAINS(error_of([&] { extra.finish(); }),
                  "--set dem.extra.sampel=2: dem.extra.sampel: unknown key; did you mean 'sample'?");
  EXPECT_EQ(extra.where(), "--set dem.extra.sampel=2");  // the override created this mapping
  EXPECT_CONTAINS(dem.child("sample").where(), "case.yaml:5");
}

// A variant case names its base (`extends`) and gives only what differs: mappings merge key by
// key, other values replace the base's, a key with no value removes the base's entry; --set goes
// over both.
TEST_F(CaseFileTest, ExtendsLaysTheVariantOverItsBase) {
  write(kCase, "base.yaml");
  const fs::path variant = write("extends: base.yaml\n"
                                 "time: {end: 2e-3}\n"
                                 "dem:\n"
                                 "  sample: {radius: 0.002, shape: sphere}\n"
                                 "  gravity:\n"
                                 "output: {fields: [c]}\n",
                                 "variant.yaml");
  CaseFile c = CaseFile::load(variant, {"time.steps=10"});
  CaseNode root = c.root();
  CaseNode time = root.child("time");
  EXPECT_DOUBLE_EQ(time.number("end", Range::positive(), "s"), 2e-3);  // the variant's
  EXPECT_EQ(time.integer("steps", Range::at_least(1)), 10);            // --set's over the base's 200
  CaseNode dem = root.child("dem");
  CaseNode sample = dem.child("sample");
  EXPECT_DOUBLE_EQ(sample.number("radius", Range::positive(), "m"), 0.002);
  EXPECT_DOUBLE_EQ(sample.number("density", Range::positive(), "kg/m^3"), 2500);  // kept from the base
  EXPECT_EQ(sample.string("shape"), "sphere");                                     // added
  EXPECT_FALSE(dem.has("gravity"));                                                // removed
  EXPECT_TRUE(dem.boolean("periodic"));
  EXPECT_EQ(root.child("output").strings("fields"), (std::vector<std::string>{"c"}));  // a list is replaced whole
  EXPECT_FALSE(root.has("extends"));
  EXPECT_EQ(c.path(), variant);
}

// An error names the file and line its entry came from: the base's, the variant's or --set's.
TEST_F(CaseFileTest, ExtendedEntriesReportTheFileTheyCameFrom) {
  write("time: {end: 1e-3}\ndem:\n  sample:\n    radius: -1\n    density: 2500\n", "base.yaml");
  write("extends: base.yaml\ndem:\n  sample:\n    density: -3\n  contakt: {}\n", "middle.yaml");
  const fs::path variant = write("extends: middle.yaml\ntime: {end: x}\n", "variant.yaml");
  CaseFile c = CaseFile::load(variant, {"dem.sample.seed=-2"});
  CaseNode root = c.root();
  EXPECT_CONTAINS(error_of([&] { root.child("time").number("end", Range::positive(), "s"); }),
                  "variant.yaml:2: time.end: expected a number > 0 [s], got 'x'");
  CaseNode dem = root.child("dem");
  CaseNode sample = dem.child("sample");
  EXPECT_CONTAINS(error_of([&] { sample.number("radius", Range::positive(), "m"); }),
                  "base.yaml:4: dem.sample.radius: expected a number > 0 [m], got -1");
  EXPECT_CONTAINS(error_of([&] { sample.number("density", Range::positive(), "kg/m^3"); }),
                  "middle.yaml:4: dem.sample.density: expected a number > 0 [kg/m^3], got -3");
  EXPECT_CONTAINS(error_of([&] { sample.integer("seed", Range::at_least(0)); }), "--set dem.sample.seed=-2: dem.sample.seed:");
  EXPECT_FALSE(dem.has("contact"));
  EXPECT_CONTAINS(error_of([&] { dem.finish(); }), "middle.yaml:5: dem.contakt: unknown key; did you mean 'contact'?");
}

TEST_F(CaseFileTest, ABadExtendsIsNamed) {
  write("time: {end: 1e-3}\n", "base.yaml");
  const auto message = [&](const std::string& text) { return error_of([&] { CaseFile::load(write(text, "v.yaml")); }); };
  EXPECT_CONTAINS(message("a: 1\nextends: nope.yaml\n"), "v.yaml:2: extends: no case file ");
  EXPECT_CONTAINS(message("extends: sub/variant.yaml\n"),
                  "v.yaml:1: extends: expected the file name of a case in this case's folder (relative paths in both are "
                  "read from it), got 'sub/variant.yaml'");
  EXPECT_CONTAINS(message("extends: [base.yaml]\n"), "v.yaml:1: extends: expected the file name of a case");
  EXPECT_CONTAINS(message("extends: base.yaml\ntime: {end: 1}\ntime: {end: 2}\n"),
                  "v.yaml:3: time: duplicate key (first given at line 2)");
  write("extends: b.yaml\n", "a.yaml");
  write("extends: a.yaml\n", "b.yaml");
  EXPECT_CONTAINS(error_of([&] { CaseFile::load(dir_ / "a.yaml"); }),
                  "b.yaml:1: extends: the cases extend one another: a.yaml -> b.yaml -> a.yaml");
  EXPECT_CONTAINS(message("extends: v.yaml\n"), "v.yaml:1: extends: the cases extend one another: v.yaml -> v.yaml");
}

TEST_F(CaseFileTest, ListItemsHavePathsAndLines) {
  CaseFile c = load("loads:\n  - group: top\n    value: 1\n  - group: bottom\n    value: x\n");
  CaseNode root = c.root();
  auto loads = root.list("loads");
  ASSERT_EQ(loads.size(), 2u);
  EXPECT_EQ(loads[1].path(), "loads[1]");
  EXPECT_EQ(loads[0].string("group"), "top");
  EXPECT_CONTAINS(error_of([&] { loads[1].number("value", Range::any(), "N"); }),
                  "case.yaml:5: loads[1].value: expected a number [N], got 'x'");
  EXPECT_CONTAINS(error_of([&] { loads[1].fail("group", "group 'bottom' is empty"); }),
                  "case.yaml:4: loads[1].group: group 'bottom' is empty");
  EXPECT_TRUE(root.list_or_empty("fixes").empty());
  EXPECT_CONTAINS(c.resolved_yaml(), "fixes: []");
}

TEST_F(CaseFileTest, UserNamedChildren) {
  CaseFile c = load("materials:\n  fibre:\n    young: 1e9\n  matrix:\n    young: 2e9\n");
  CaseNode materials = c.root().child("materials");
  for (const auto& name : materials.keys()) {
    CaseNode m = materials.child_named(name);
    EXPECT_GT(m.number("young", Range::positive(), "Pa"), 0);
    m.finish();
  }
  materials.finish();
  CaseFile d = load("materials:\n  fibre: {}\n  glass: {}\n");
  CaseNode all = d.root().child("materials");
  all.child_named("fibre");
  EXPECT_CONTAINS(error_of([&] { all.finish(); }), "materials.glass: unknown key; no keys are expected here");
  all.accept_any_keys();
  all.finish();
}

TEST_F(CaseFileTest, ExistingFileIsRelativeToCaseFolder) {
  write("Point(1) = {0, 0, 0};\n", "cases/meshes/x.geo");
  const fs::path file = write("mesh: meshes/x.geo\nother: meshes/y.geo\n", "cases/case.yaml");
  CaseNode root = CaseFile::load(file).root();
  EXPECT_EQ(root.existing_file("mesh"), dir_ / "cases/meshes/x.geo");
  EXPECT_CONTAINS(error_of([&] { root.existing_file("other"); }),
                  "case.yaml:2: other: file 'meshes/y.geo' not found (looked in " +
                      (dir_ / "cases/meshes").string() + ")");
}

TEST_F(CaseFileTest, RangesAndEditDistance) {
  EXPECT_EQ(Range::positive().describe(), "> 0");
  EXPECT_EQ(Range::between(0, 1).describe(), "in [0, 1]");
  EXPECT_EQ(Range::open_between(0, 0.5).describe(), "in (0, 0.5)");
  EXPECT_EQ(Range::any().describe(), "");
  EXPECT_FALSE(Range::positive().contains(0));
  EXPECT_TRUE(Range::non_negative().contains(0));
  EXPECT_FALSE(Range::open_between(0, 1).contains(1));
  EXPECT_EQ(edit_distance("sampel", "sample"), 2u);
  EXPECT_EQ(edit_distance("", "abc"), 3u);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
}

}  // namespace
}  // namespace arlequin

namespace arlequin {
namespace {

// With a schema, each read is checked against the declared key: an undeclared key, or one read
// with another type, unit, range, choice list or literal default, is a logic error (a bug of the
// program, not of the case); sections nest by the declaring key, lists get "[]", user-chosen
// names "<name>", and a registry entry's keys come in with add_schema_section. Reads are recorded.
TEST_F(CaseFileTest, ASchemaChecksEveryReadAgainstItsDeclaration) {
  constexpr KeyDoc top[] = {
      {"time", KeyType::section, "", {}, "", "times"},
      {"items", KeyType::list, "", {}, "(none)", "a list"},
      {"materials", KeyType::names, "", {}, "(none)", "named"},
  };
  constexpr KeyDoc time[] = {
      {"end", KeyType::number, "s", Range::positive(), "", "end"},
      {"safety", KeyType::number, "1", Range::open_between(0, 1), "0.3", "fraction"},
      {"mode", KeyType::choice, "", {}, "a", "mode", "a | b"},
      {"count", KeyType::integer, "", Range::at_least(1), "(computed)", "a computed default"},
  };
  constexpr KeyDoc item[] = {{"x", KeyType::number, "(by type)", {}, "", "unit by type"}};
  constexpr KeyDoc named[] = {{"<name>", KeyType::section, "", {}, "", "one"}};
  constexpr KeyDoc material[] = {{"rho", KeyType::number, "kg/m^3", Range::positive(), "", "density"}};
  constexpr KeyDoc law[] = {{"k", KeyType::number, "N/m", Range::positive(), "", "stiffness"}};
  const Schema schema({{"", "top", top},
                       {"time", "", time},
                       {"items[]", "", item},
                       {"materials", "", named},
                       {"materials.<name>", "", material},
                       {"time (law: x)", "", law}});
  const fs::path file = write("time: {end: 1, k: 2}\nitems: [{x: 1}]\nmaterials: {steel: {rho: 7800}}\n");
  CaseNode root = CaseFile::load(file, {}, &schema).root();
  CaseNode t = root.child("time");
  EXPECT_EQ(t.number("end", Range::positive(), "s"), 1.0);
  EXPECT_EQ(t.number_or("safety", 0.3, Range::open_between(0, 1), "1"), 0.3);
  static constexpr std::string_view modes[] = {"a", "b"};
  EXPECT_EQ(t.choice_or("mode", "a", modes), "a");
  EXPECT_EQ(t.integer_or("count", 7, Range::at_least(1)), 7);  // "(...)": any default
  EXPECT_THROW(t.number("end", Range::non_negative(), "s"), std::logic_error);           // another range
  EXPECT_THROW(t.number("end", Range::positive(), "ms"), std::logic_error);              // another unit
  EXPECT_THROW(t.number_or("safety", 0.5, Range::open_between(0, 1), "1"), std::logic_error);  // another default
  EXPECT_THROW(t.integer("end", Range::positive()), std::logic_error);                   // another type
  static constexpr std::string_view other_modes[] = {"a", "c"};
  EXPECT_THROW(t.choice("mode", other_modes), std::logic_error);                         // other choices
  EXPECT_THROW(t.number_or("stop", 1.0, Range::any(), "s"), std::logic_error);           // undeclared
  EXPECT_THROW(t.number("k", Range::positive(), "N/m"), std::logic_error);               // not yet added
  t.add_schema_section("time (law: x)");
  EXPECT_EQ(t.number("k", Range::positive(), "N/m"), 2.0);
  EXPECT_EQ(root.list("items").at(0).number("x", Range::any(), "m"), 1.0);  // "(by type)": any unit
  CaseNode materials = root.child("materials");
  EXPECT_EQ(materials.child_named("steel").number("rho", Range::positive(), "kg/m^3"), 7800.0);
  for (const char* read : {"|time", "time|end", "time|safety", "time (law: x)|k", "items[]|x", "materials|<name>", "materials.<name>|rho"})
    EXPECT_TRUE(schema.read().contains(read)) << read;
  EXPECT_FALSE(schema.read().contains("time|stop"));
}

}  // namespace
}  // namespace arlequin
