#include "app/scene.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <numbers>
#include <optional>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "app/case_schema.hpp"
#include "common/case_file.hpp"
#include "common/error.hpp"
#include "common/region.hpp"
#include "common/schema.hpp"
#include "dem/sample_file.hpp"
#include "dem/samples.hpp"

namespace arlequin::app {
namespace {

using dem::BoundaryCondition;
using dem::BoundaryKind;

constexpr std::string_view component_names[] = {"x", "y", "z", "all"};

// ---- The schema of the sections read here (common/schema.hpp) ---------------------------

constexpr KeyDoc top_keys[] = {
    {"name", KeyType::string, "", {}, "(the case folder's name)", "the case's name, used for the default output folder"},
    {"units", KeyType::choice, "", {}, "SI", "unit system of every number in the case", "SI"},
    {"time", KeyType::section, "", {}, "", "the time span and step"},
    {"dem", KeyType::section, "", {}, "(none)", "the discrete elements: sample, bonds, contact, damping, failure"},
    {"continuum", KeyType::section, "", {}, "(none)", "a continuum model (see continuum)"},
    {"coupling", KeyType::section, "", {}, "(none)", "Arlequin coupling of the DEM zone and the continuum (see coupling)"},
    {"groups", KeyType::list, "", {}, "(none)", "named sets of DEs, by region or by index"},
    {"boundary", KeyType::list, "", {}, "(none)", "DEM boundary conditions, one per group"},
    {"initial", KeyType::list, "", {}, "(none)", "initial velocities of groups of DEs"},
    {"initial_strain", KeyType::section, "", {}, "(none)", "a uniform initial displacement gradient of both models"},
    {"pulse", KeyType::section, "", {}, "(none)", "an initial velocity pulse travelling along a direction"},
    {"sensors", KeyType::list, "", {}, "(none)", "series.csv columns: forces, displacements, velocities, energies of groups"},
    {"checks", KeyType::list, "", {}, "(none)", "acceptance checks of series columns against references"},
    {"output", KeyType::section, "", {}, "(defaults)", "where and how often results are written"},
};
constexpr KeyDoc time_keys[] = {
    {"end", KeyType::number, "s", Range::positive(), "", "simulated time at which the run ends"},
    {"dt", KeyType::number_or_auto, "s", Range::positive(), "auto", "time step; auto: safety x the critical step, a larger one is refused"},
    {"safety", KeyType::number, "1", Range::open_between(0, 1), "0.3", "fraction of the critical time step taken by dt: auto"},
};
constexpr KeyDoc dem_keys[] = {
    {"sample", KeyType::section, "", {}, "", "how the DEs are placed (lattice, chain, particles, packing)"},
    {"density", KeyType::number, "kg/m^3", Range::positive(), "(none)", "DE density, with one bond law for all (else materials)"},
    {"bond", KeyType::section, "", {}, "(none)", "bonds between every two DEs that touch, one law for all"},
    {"materials", KeyType::names, "", {}, "(none)", "materials by name, each with its density, region and bond law"},
    {"interface", KeyType::section, "", {}, "(none)", "the bond law between DEs of two different materials"},
    {"bond_tolerance", KeyType::number, "1", Range::between(0, 1), "(the packing's, else 0.01)", "gap, over the mean radius, below which two DEs of materials bond"},
    {"contact", KeyType::section, "", {}, "(none)", "contact between DEs that are not bonded (a neighbour search)"},
    {"damping", KeyType::number, "1/s", Range::non_negative(), "0", "viscous damping of DE velocities, c in dv/dt = ... - c v"},
    {"failure", KeyType::section, "", {}, "(none)", "failure criteria beyond the bond laws' own (RDEF)"},
};
constexpr KeyDoc sample_keys[] = {
    {"build", KeyType::choice, "", {}, "", "how the DEs are made", "lattice | chain | particles | packing"},
    {"radius", KeyType::number, "m", Range::positive(), "(none)", "DE radius (lattice, chain); a packing gives a distribution instead"},
    {"spacing", KeyType::number, "m", Range::positive(), "(2 radius)", "centre distance of neighbours (lattice, chain)"},
    {"origin", KeyType::vec3, "m", {}, "[0, 0, 0]", "centre of the lattice's first DE"},
    {"counts", KeyType::numbers, "1", Range::at_least(1), "", "DEs along x, y, z (lattice)"},
    {"start", KeyType::vec3, "m", {}, "[0, 0, 0]", "centre of the chain's first DE"},
    {"direction", KeyType::vec3, "1", {}, "[1, 0, 0]", "direction of the chain"},
    {"count", KeyType::integer, "", Range::at_least(1), "", "DEs in the chain"},
    {"particles", KeyType::list, "", {}, "", "the DEs one by one (particles)"},
    {"region", KeyType::section, "", {}, "", "the region the packing fills (a region: box, cylinder, sphere)"},
    {"compaction", KeyType::number, "1", Range::open_between(0, 0.7), "0.63", "target solid fraction of the packing"},
    {"min_coordination", KeyType::number, "1", Range::non_negative(), "6", "mean number of bonded neighbours the packing must reach"},
    {"seed", KeyType::integer, "", Range::non_negative(), "1", "random seed of the packing"},
    {"bond_tolerance", KeyType::number, "1", Range::between(0, 0.5), "0.03", "gap, over the mean radius, that counts as contact in the packing"},
    {"file", KeyType::string, "", {}, "(results/<name>/sample.h5)", "where the packing is cached (HDF5), relative to the case"},
};
constexpr KeyDoc radius_distribution_keys[] = {
    {"mean", KeyType::number, "m", Range::positive(), "", "mean DE radius"},
    {"std", KeyType::number, "1", Range::between(0, 0.5), "0.15", "standard deviation over the mean (truncated Gaussian)"},
    {"truncation", KeyType::number, "1", Range::positive(), "2", "radii beyond mean +- truncation x std are drawn again"},
};
constexpr KeyDoc particle_keys[] = {
    {"position", KeyType::vec3, "m", {}, "", "centre of the DE"},
    {"radius", KeyType::number, "m", Range::positive(), "", "radius of the DE"},
    {"velocity", KeyType::vec3, "m/s", {}, "[0, 0, 0]", "initial velocity"},
};
constexpr KeyDoc bond_law_key{"law", KeyType::choice, "", {}, "", "the bond law (arlequin laws); its own keys follow in 'bond (law: ...)'",
                              "beam | spring"};
constexpr KeyDoc dem_bond_keys[] = {
    bond_law_key,
    {"tolerance", KeyType::number, "1", Range::between(0, 1), "(the packing's, else 0.01)", "gap, over the mean radius, below which two DEs bond"},
};
constexpr KeyDoc material_bond_keys[] = {bond_law_key};
constexpr KeyDoc contact_keys[] = {
    {"law", KeyType::choice, "", {}, "", "the contact law (arlequin laws); its own keys follow in 'contact (law: ...)'", "penalty"},
    {"skin", KeyType::number, "m", Range::positive(), "(0.2 x the mean radius)", "neighbour list margin: rebuilt when a DE has moved half of it"},
};
constexpr KeyDoc materials_keys[] = {
    {"<name>", KeyType::section, "", {}, "", "one material, under a name of the user's"},
};
constexpr KeyDoc material_keys[] = {
    {"density", KeyType::number, "kg/m^3", Range::positive(), "", "density of the material's DEs"},
    {"region", KeyType::section, "", {}, "(everywhere else)", "where the material is; one material may go without"},
    {"bond", KeyType::section, "", {}, "", "the bond law between two DEs of this material"},
};
constexpr KeyDoc interface_keys[] = {
    {"bond", KeyType::section, "", {}, "", "the bond law between DEs of two different materials"},
};
constexpr KeyDoc failure_keys[] = {
    {"rdef", KeyType::section, "", {}, "(none)", "virial-stress element failure: all bonds of a DE break (docs/theory.md#rdef)"},
};
constexpr KeyDoc rdef_keys[] = {
    {"threshold", KeyType::number, "(Pa)", Range::positive(), "(none)", "equivalent stress at which a DE fails (the materials without their own)"},
    {"material_thresholds", KeyType::section, "", {}, "(none)", "threshold per material name, Pa"},
    {"equivalent", KeyType::choice, "", {}, "max_principal", "equivalent stress of the DE's virial", "max_principal | von_mises | hydrostatic"},
    {"average", KeyType::choice, "", {}, "none", "average the stress over the DE's bonded neighbours of its material",
     "none | bonded_neighbours"},
    {"volume", KeyType::choice, "", {}, "sphere", "a DE's volume share: its sphere over compaction, or its Laguerre cell", "sphere | laguerre"},
    {"compaction", KeyType::number, "1", Range::open_between(0, 1), "0.63", "solid fraction dividing sphere volumes (volume: sphere)"},
};
constexpr KeyDoc material_threshold_keys[] = {
    {"<name>", KeyType::number, "Pa", Range::positive(), "", "RDEF threshold of that material"},
};
constexpr KeyDoc group_keys[] = {
    {"name", KeyType::string, "", {}, "", "the group's name (at most 32 groups, materials included)"},
    {"region", KeyType::section, "", {}, "(none)", "the DEs whose centre lies in this region"},
    {"ids", KeyType::numbers, "(DE index, 0 to count - 1)", {}, "(none)", "the DEs of these indices"},
};
constexpr KeyDoc boundary_keys[] = {
    {"group", KeyType::string, "", {}, "", "the group it acts on"},
    {"type", KeyType::choice, "", {}, "", "what it imposes", "fixed | velocity | displacement | force | free"},
    {"value", KeyType::vec3, "(m/s, m or N by type)", {}, "", "the imposed velocity, displacement or total force"},
    {"components", KeyType::strings, "", {}, "(x, y, z)", "the components it acts on"},
    {"rise", KeyType::number, "s", Range::non_negative(), "0", "time over which the value rises linearly from 0"},
    {"ramp", KeyType::number, "s", Range::positive(), "(none)", "displacement: time over which it is reached"},
    {"rotation", KeyType::choice, "", {}, "free", "whether the DEs' rotations are held", "free | fixed"},
};
constexpr KeyDoc initial_keys[] = {
    {"group", KeyType::string, "", {}, "", "the group whose DEs start moving"},
    {"velocity", KeyType::vec3, "m/s", {}, "[0, 0, 0]", "their initial velocity"},
    {"angular_velocity", KeyType::vec3, "rad/s", {}, "[0, 0, 0]", "their initial angular velocity"},
};
constexpr KeyDoc initial_strain_keys[] = {
    {"gradient", KeyType::vec3_list, "1", {}, "", "displacement gradient H by rows: u = H X on every DE and node"},
};
constexpr KeyDoc pulse_keys[] = {
    {"group", KeyType::string, "", {}, "", "the DEs given the pulse's velocity"},
    {"direction", KeyType::vec3, "1", {}, "", "direction of travel"},
    {"center", KeyType::vec3, "m", {}, "", "the pulse's centre at t = 0"},
    {"wavelength", KeyType::number, "m", Range::positive(), "", "its length (raised cosine) or its wavelength (tone burst)"},
    {"amplitude", KeyType::number, "m/s", {}, "", "peak particle velocity"},
    {"speed", KeyType::number, "m/s", Range::positive(), "", "wave speed, for the matching displacement field"},
    {"cycles", KeyType::integer, "", Range::at_least(1), "(none)", "a Hann-windowed tone burst of this many cycles instead"},
};
constexpr KeyDoc sensor_keys[] = {
    {"name", KeyType::string, "", {}, "", "column name (with _x, _y, _z per component)"},
    {"type", KeyType::choice, "", {}, "", "what it measures", "force | displacement | velocity | energy | affine_deviation"},
    {"on", KeyType::choice, "", {}, "(dem if the case has DEs)", "which model's group", "dem | continuum"},
    {"group", KeyType::string, "", {}, "", "the group measured (reaction force, mean displacement or velocity, energy)"},
    {"component", KeyType::choice, "", {}, "all", "one component, or all three", "x | y | z | all"},
};
constexpr KeyDoc check_keys[] = {
    {"column", KeyType::string, "", {}, "", "the series.csv column judged"},
    {"statistic", KeyType::choice, "", {}, "final", "what of the column is judged", "final | max | min | final_over_initial"},
    {"crossing", KeyType::number, "column unit", {}, "(none)", "judge the time the column first reaches this value instead"},
    {"expected", KeyType::number, "(the column's, or s)", {}, "(none)", "reference value (with tolerance)"},
    {"tolerance", KeyType::number, "1", Range::positive(), "", "relative tolerance on expected"},
    {"at_most", KeyType::number, "column unit", {}, "(none)", "upper bound (instead of expected)"},
    {"at_least", KeyType::number, "column unit", {}, "(none)", "lower bound (instead of expected)"},
    {"note", KeyType::string, "", {}, "", "where the reference comes from, shown with the result"},
};
constexpr KeyDoc output_keys[] = {
    {"dir", KeyType::string, "", {}, "(results/<name>)", "output folder, relative to the working directory"},
    {"every", KeyType::number, "s", Range::positive(), "(time.end / 100)", "interval of series.csv rows"},
    {"fields", KeyType::strings, "", {}, "[]", "field sets written to fields.h5: particles, bonds, continuum"},
    {"fields_every", KeyType::number, "s", Range::positive(), "(every)", "interval of fields.h5 frames"},
    {"plots", KeyType::list, "", {}, "(none)", "plots of series columns, drawn by the Python package"},
};
constexpr KeyDoc plot_keys[] = {
    {"file", KeyType::string, "", {}, "", "image name in the output folder: .png, .svg or .pdf"},
    {"title", KeyType::string, "", {}, "", "title"},
    {"x", KeyType::string, "", {}, "", "column on the x axis"},
    {"x_scale", KeyType::number, "1", {}, "1", "factor on x (e.g. 1 / L for a strain)"},
    {"x_label", KeyType::string, "", {}, "(x)", "x axis label"},
    {"y", KeyType::strings, "", {}, "", "columns on the left axis"},
    {"y_scale", KeyType::number, "1", {}, "1", "factor on the left axis' columns"},
    {"y_label", KeyType::string, "", {}, "", "left axis label"},
    {"y2", KeyType::strings, "", {}, "[]", "columns on the right axis"},
    {"y2_scale", KeyType::number, "1", {}, "1", "factor on the right axis' columns"},
    {"y2_label", KeyType::string, "", {}, "", "right axis label"},
};

constexpr SchemaSection scene_sections[] = {
    {"", "a case file's top-level sections", top_keys},
    {"time", "time span and step", time_keys},
    {"dem", "the discrete elements", dem_keys},
    {"dem.sample", "how the DEs are placed", sample_keys},
    {"dem.sample.radius", "radius distribution of a packing (truncated Gaussian)", radius_distribution_keys},
    {"dem.sample.particles[]", "one DE of build: particles", particle_keys},
    {"dem.bond", "bonds of every touching pair, one law", dem_bond_keys},
    {"dem.materials", "materials by name", materials_keys},
    {"dem.materials.<name>", "one material", material_keys},
    {"dem.materials.<name>.bond", "the material's bond law", material_bond_keys},
    {"dem.interface", "between materials", interface_keys},
    {"dem.interface.bond", "the bond law between materials", material_bond_keys},
    {"dem.contact", "contact of unbonded DEs", contact_keys},
    {"dem.failure", "failure criteria", failure_keys},
    {"dem.failure.rdef", "RDEF (virial stress of a DE)", rdef_keys},
    {"dem.failure.rdef.material_thresholds", "RDEF threshold per material", material_threshold_keys},
    {"groups[]", "a named group of DEs (a region or ids)", group_keys},
    {"boundary[]", "a DEM boundary condition", boundary_keys},
    {"initial[]", "an initial velocity", initial_keys},
    {"initial_strain", "a uniform initial strain", initial_strain_keys},
    {"pulse", "an initial velocity pulse", pulse_keys},
    {"sensors[]", "a series.csv column (or three)", sensor_keys},
    {"checks[]", "an acceptance check judged at time.end", check_keys},
    {"output", "results", output_keys},
    {"output.plots[]", "a plot of series columns", plot_keys},
};

// A dense random packing (dem/packing.hpp), cached in an HDF5 sample file: built once, then
// loaded while the file's spec matches the case's.
void read_packing(CaseNode sample, Scene& scene, double density, const SceneOptions& options) {
  dem::PackingSpec spec{Region(Box{}), 0.0, 0.0};
  CaseNode region = sample.child("region");
  spec.region = Region::read(region);
  region.finish();
  CaseNode radius = sample.child("radius");
  spec.mean_radius = radius.number("mean", Range::positive(), "m");
  spec.relative_std = radius.number_or("std", 0.15, Range::between(0.0, 0.5), "1");
  spec.truncation = radius.number_or("truncation", 2.0, Range::positive(), "1");
  radius.finish();
  spec.target_compaction = sample.number_or("compaction", 0.63, Range::open_between(0.0, 0.7), "1");
  spec.min_coordination = sample.number_or("min_coordination", 6.0, Range::non_negative(), "1");
  spec.seed = static_cast<std::uint64_t>(sample.integer_or("seed", 1, Range::at_least(0)));
  spec.bond_tolerance = sample.number_or("bond_tolerance", 0.03, Range::between(0.0, 0.5), "1");
  std::filesystem::path file = sample.string_or("file", "results/" + scene.name + "/sample.h5");
  if (file.is_relative()) file = scene.case_file.parent_path() / file;
  scene.sample_file = file;
  dem::ParticleSet& p = scene.dem.particles;
  if (!options.rebuild_sample && std::filesystem::exists(file)) {
    dem::ParticleSet loaded;
    dem::SampleRecord record = dem::load_sample(file, loaded, density);
    if (record.spec == spec) {
      p = std::move(loaded);
      scene.sample = std::move(record);
      return;
    }
  }
  try {
    scene.sample = dem::SampleRecord{spec, dem::build_packing(p, spec, density)};
  } catch (const std::invalid_argument& e) {
    sample.fail("region", e.what());
  } catch (const RunError& e) {
    sample.fail("compaction", e.what());
  }
  dem::save_sample(file, p, spec, scene.sample->report);
}

void read_sample(CaseNode sample, Scene& scene, double density, const SceneOptions& options) {
  static constexpr std::string_view builders[] = {"lattice", "chain", "particles", "packing"};
  dem::ParticleSet& p = scene.dem.particles;
  const std::string build = sample.choice("build", builders);
  if (build == "packing") {
    read_packing(sample, scene, density, options);
  } else if (build == "lattice") {
    const Vec3 origin = sample.vec3_or("origin", {}, Range::any(), "m");
    const auto counts = sample.numbers("counts", Range::at_least(1), "1");
    if (counts.size() != 3) sample.fail("counts", "expected three DE counts [nx, ny, nz]");
    for (double c : counts)
      if (c != std::floor(c)) sample.fail("counts", "expected whole numbers");
    const double radius = sample.number("radius", Range::positive(), "m");
    const double spacing = sample.number_or("spacing", 2.0 * radius, Range::positive(), "m");
    dem::build_lattice(p, origin, {int(counts[0]), int(counts[1]), int(counts[2])}, spacing, radius, density);
  } else if (build == "chain") {
    const Vec3 start = sample.vec3_or("start", {}, Range::any(), "m");
    const Vec3 direction = sample.vec3_or("direction", {1, 0, 0}, Range::any(), "1");
    if (!(norm(direction) > 0.0)) sample.fail("direction", "expected a non-zero direction vector");
    const auto count = sample.integer("count", Range::at_least(1));
    const double radius = sample.number("radius", Range::positive(), "m");
    const double spacing = sample.number_or("spacing", 2.0 * radius, Range::positive(), "m");
    dem::build_chain(p, start, normalized(direction), int(count), spacing, radius, density);
  }
  // Coupled: the built DEs beyond the overlap (in the pure-continuum zone) are not created.
  if (scene.continuum)
    scene.des_not_created = p.keep_only([&](std::size_t i) { return scene.continuum->in_dem_domain(p.position[i]); });
  // Explicit DEs (an impactor, a two-body test), after the built ones; the only ones for
  // build: particles.
  const auto listed = build == "particles" ? sample.list("particles") : sample.list_or_empty("particles");
  for (CaseNode item : listed) {
    const Vec3 x = item.vec3("position", Range::any(), "m");
    if (scene.continuum && !scene.continuum->in_dem_domain(x))
      item.fail("position", "this DE lies beyond the coupling overlap, in the pure-continuum zone");
    const std::size_t i = p.add(x, item.number("radius", Range::positive(), "m"), density);
    p.velocity[i] = item.vec3_or("velocity", {}, Range::any(), "m/s");
    item.finish();
  }
  sample.finish();
}

// Default bond tolerance: the packing's own (its coordination was checked with it), else 1 %.
double default_bond_tolerance(const Scene& scene) { return scene.sample ? scene.sample->spec.bond_tolerance : 0.01; }

void read_bonds(CaseNode bond, dem::DemModel& model, double default_tolerance) {
  const double tolerance = bond.number_or("tolerance", default_tolerance, Range::between(0.0, 1.0), "1");
  dem::BondSet& set = model.add_bond_set(dem::make_bond_set(bond));
  set.name = "bonds";
  bond.finish();
  for (auto [i, j] : dem::close_pairs(model.particles, tolerance)) set.add(i, j, model.particles);
  if (set.size() == 0)
    bond.fail("tolerance", "no pair of DEs is close enough to bond; raise the tolerance or remove 'bond'");
}

// Several materials (e.g. a fibre cylinder in a matrix cube): each DE takes the first material
// whose region holds it, or the one material without a region; it gets that material's density
// and a group named after it. A bond between two DEs of one material uses that material's bond
// law and parameters; a bond across materials uses dem.interface. Bond sets are named after
// their material (and "interface"), so records and outputs say fibre, matrix, interface.
std::vector<std::string> read_materials(CaseNode dem_node, dem::DemModel& model, double default_tolerance) {
  CaseNode materials = dem_node.child("materials");
  struct Material {
    std::string name;
    std::optional<Region> region;
    double density;
    std::optional<CaseNode> bond;
  };
  std::vector<Material> list;
  int fallback = -1;
  for (const std::string& name : materials.keys()) {
    CaseNode m = materials.child_named(name);
    Material mat{name, std::nullopt, m.number("density", Range::positive(), "kg/m^3"), m.child_if("bond")};
    if (auto region = m.child_if("region")) {
      mat.region = Region::read(*region);
      region->finish();
    } else if (fallback >= 0) {
      m.fail("region", "only one material may go without a region (the rest of the sample); '" +
                           list[fallback].name + "' already does");
    } else {
      fallback = int(list.size());
    }
    list.push_back(mat);
  }
  if (list.empty()) dem_node.fail("materials", "expected at least one material");
  // Regions first, in file order; the region-less material takes the rest.
  dem::ParticleSet& p = model.particles;
  std::vector<int> material_of(p.size(), -1);
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t m = 0; m < list.size() && material_of[i] < 0; ++m)
      if (list[m].region && list[m].region->contains(p.position[i])) material_of[i] = int(m);
    if (material_of[i] < 0) material_of[i] = fallback;
    if (material_of[i] < 0) {
      std::ostringstream msg;
      msg << "DE " << i << " at (" << p.position[i].x << ", " << p.position[i].y << ", " << p.position[i].z
          << ") m is in no material's region; give one material no region to take the rest";
      dem_node.fail("materials", msg.str());
    }
    // The sample was built with unit density: scale the mass to the material's.
    p.inv_mass[i] /= list[material_of[i]].density;
  }
  std::vector<int> group(list.size());
  for (std::size_t m = 0; m < list.size(); ++m) group[m] = model.add_group(list[m].name);
  for (std::size_t i = 0; i < p.size(); ++i) p.groups[i] |= dem::GroupMask{1} << group[material_of[i]];

  // One bond set per material with a bond law, and one for the interfaces.
  const double tolerance = dem_node.number_or("bond_tolerance", default_tolerance, Range::between(0.0, 1.0), "1");
  std::vector<dem::BondSet*> set_of(list.size(), nullptr);
  for (std::size_t m = 0; m < list.size(); ++m) {
    if (!list[m].bond) continue;
    set_of[m] = &model.add_bond_set(dem::make_bond_set(*list[m].bond));
    set_of[m]->name = list[m].name;
    list[m].bond->finish();
  }
  dem::BondSet* interface = nullptr;
  if (auto section = dem_node.child_if("interface")) {
    CaseNode bond = section->child("bond");
    interface = &model.add_bond_set(dem::make_bond_set(bond));
    interface->name = "interface";
    bond.finish();
    section->finish();
  }
  for (auto [i, j] : dem::close_pairs(p, tolerance)) {
    const int a = material_of[i], b = material_of[j];
    dem::BondSet* set = a == b ? set_of[a] : interface;
    if (set) set->add(i, j, p);
  }
  std::vector<std::string> names;
  for (std::size_t m = 0; m < list.size(); ++m) {
    materials.child_named(list[m].name).finish();
    names.push_back(list[m].name);
  }
  return names;
}

// `materials`: the case's material names (empty without dem.materials).
void read_failure(CaseNode failure, dem::DemModel& model, const std::vector<std::string>& materials) {
  // BBF strengths belong to the bond laws (sigma_f, max_elongation); RDEF is per DE, with a
  // threshold per material (material_thresholds) or one for every DE (threshold).
  if (auto rdef = failure.child_if("rdef")) {
    static constexpr std::string_view equivalents[] = {"max_principal", "von_mises", "hydrostatic"};
    dem::DemModel::RdefSettings settings;
    std::vector<std::string> missing = materials;
    if (auto per_material = rdef->child_if("material_thresholds")) {
      if (materials.empty()) rdef->fail("material_thresholds", "needs dem.materials; give one threshold instead");
      for (const std::string& name : per_material->keys()) {
        const auto it = std::find(missing.begin(), missing.end(), name);
        if (it == missing.end()) per_material->fail(name, "no material of that name (or listed twice)");
        missing.erase(it);
        settings.group_thresholds.emplace_back(model.group_index(name), per_material->number(name, Range::positive(), "Pa"));
      }
      per_material->finish();
    }
    if (materials.empty() || !missing.empty()) {
      std::string which;
      for (const auto& m : missing) which += (which.empty() ? "" : ", ") + m;
      settings.threshold = rdef->number("threshold", Range::positive(),
                                        materials.empty() ? "Pa" : "Pa (for the materials without their own: " + which + ")");
    } else {
      settings.threshold = std::numeric_limits<double>::infinity();  // every DE has its material's
      if (rdef->has("threshold")) rdef->fail("threshold", "every material has its own threshold in material_thresholds");
    }
    const std::string equivalent = rdef->choice_or("equivalent", "max_principal", equivalents);
    settings.equivalent = equivalent == "von_mises"     ? dem::RdefEquivalent::von_mises
                          : equivalent == "hydrostatic" ? dem::RdefEquivalent::hydrostatic
                                                        : dem::RdefEquivalent::max_principal;
    static constexpr std::string_view averages[] = {"none", "bonded_neighbours"};
    settings.average = rdef->choice_or("average", "none", averages) == "bonded_neighbours" ? dem::RdefAverage::bonded_neighbours
                                                                                            : dem::RdefAverage::none;
    static constexpr std::string_view volumes[] = {"sphere", "laguerre"};
    settings.volume = rdef->choice_or("volume", "sphere", volumes) == "laguerre" ? dem::RdefVolume::laguerre : dem::RdefVolume::sphere;
    if (settings.volume == dem::RdefVolume::laguerre && rdef->has("compaction"))
      rdef->fail("compaction", "only for volume: sphere (a Laguerre cell needs no compaction)");
    settings.compaction = rdef->number_or("compaction", 0.63, Range::open_between(0.0, 1.0), "1");
    rdef->finish();
    model.enable_rdef(settings);
  }
  failure.finish();
}

void read_groups(CaseNode root, dem::DemModel& model) {
  for (CaseNode g : root.list_or_empty("groups")) {
    const std::string name = g.string("name");
    if (model.group_index(name) >= 0) g.fail("name", "group '" + name + "' is defined twice");
    if (model.group_names().size() >= static_cast<std::size_t>(dem::max_groups))
      g.fail("name", "too many groups (at most 32)");
    const int index = model.add_group(name);
    const dem::GroupMask bit = dem::GroupMask{1} << index;
    dem::ParticleSet& p = model.particles;
    std::size_t count = 0;
    if (g.has("ids")) {
      for (double id : g.numbers("ids", Range::between(0, double(p.size()) - 1), "1")) {
        if (id != std::floor(id)) g.fail("ids", "expected whole DE indices");
        p.groups[std::size_t(id)] |= bit, ++count;
      }
    } else {
      CaseNode region_node = g.child("region");
      const Region region = Region::read(region_node);
      region_node.finish();
      for (std::size_t i = 0; i < p.size(); ++i)
        if (region.contains(p.position[i])) p.groups[i] |= bit, ++count;
    }
    if (count == 0) g.fail(g.has("ids") ? "ids" : "region", "group '" + name + "' contains no DE");
    g.finish();
  }
}

int group_of(CaseNode& node, const dem::DemModel& model) {
  const std::string name = node.string("group");
  const int g = model.group_index(name);
  if (g < 0) {
    std::string known;
    for (const auto& n : model.group_names()) known += (known.empty() ? "" : ", ") + n;
    node.fail("group", "unknown group '" + name + "' (defined groups: " + (known.empty() ? "none" : known) + ")");
  }
  return g;
}

void read_boundary(CaseNode root, dem::DemModel& model) {
  static constexpr std::string_view kinds[] = {"fixed", "velocity", "displacement", "force", "free"};
  static constexpr std::string_view rotations[] = {"free", "fixed"};
  std::vector<CaseNode> entries = root.list_or_empty("boundary");
  for (CaseNode b : entries) {
    BoundaryCondition bc;
    group_of(b, model);
    bc.group = b.string("group");
    const std::string kind = b.choice("type", kinds);
    if (kind == "fixed") {
      bc.kind = BoundaryKind::fixed;
      bc.lock_rotation = true;
    } else if (kind == "free") {
      bc.kind = BoundaryKind::free;
    } else {
      bc.kind = kind == "velocity" ? BoundaryKind::velocity
                : kind == "displacement" ? BoundaryKind::displacement : BoundaryKind::force;
      bc.value = b.vec3("value", Range::any(), kind == "velocity" ? "m/s" : kind == "force" ? "N" : "m");
      if (bc.kind == BoundaryKind::displacement) bc.ramp = b.number("ramp", Range::positive(), "s");
      if (bc.kind == BoundaryKind::velocity) bc.rise = b.number_or("rise", 0.0, Range::non_negative(), "s");
      if (bc.kind != BoundaryKind::force) bc.lock_rotation = b.choice_or("rotation", "free", rotations) == "fixed";
    }
    if (bc.kinematic() && b.has("components")) {
      bc.components = {false, false, false};
      for (const std::string& c : b.strings("components")) {
        if (c != "x" && c != "y" && c != "z") b.fail("components", "expected a list of x, y, z, got '" + c + "'");
        bc.components[c[0] - 'x'] = true;
      }
    }
    b.finish();
    model.add_boundary(bc);
  }
}

// Finalizes the DEM and chooses the scene's model: coupled when the case couples the DEM to the
// continuum (the coupling finalizes the DEM), else each with its own step. A contradiction
// between boundary conditions is reported at the boundary section.
void finalize_models(CaseNode root, Scene& scene, bool coupled) {
  if (coupled && scene.dem.particles.size() == 0)
    root.fail("coupling", "no DE of the sample lies in the DEM domain (the pure-DEM zone and the overlap)");
  try {
    if (coupled) {
      scene.model = scene.continuum->couple(scene.dem);
    } else {
      scene.dem.finalize();
      scene.model = uncoupled_scene_model(scene.dem, scene.continuum.get());
    }
  } catch (const std::invalid_argument& e) {
    if (root.has("boundary")) root.fail("boundary", e.what());
    throw InputError(root.where() + ": " + e.what());
  }
}

void read_initial(CaseNode root, dem::DemModel& model) {
  for (CaseNode item : root.list_or_empty("initial")) {
    const int g = group_of(item, model);
    const Vec3 v = item.vec3_or("velocity", {}, Range::any(), "m/s");
    const Vec3 w = item.vec3_or("angular_velocity", {}, Range::any(), "rad/s");
    item.finish();
    for (std::uint32_t i : model.members(g)) {
      model.particles.velocity[i] = v;
      model.particles.angular_velocity[i] = w;
    }
  }
}

// A velocity pulse travelling along d at speed c, s = (x - center).d, of one of two shapes:
//   raised cosine (default): v(s) = A (1 + cos(k s)) / 2 for |s| < lambda / 2;
//   tone burst (`cycles: N`): v(s) = A sin(k s) (1 + cos(k s / N)) / 2 for |s| < N lambda / 2,
//     N cycles of wavelength lambda under a Hann window: a narrow band about k (half-width
//     k / N at half height), to probe one frequency (e.g. above a continuum's cut-off);
// k = 2 pi / lambda, v = 0 outside. Both are sums of A_m cos(m s + phase) terms; the displacement
//   u(s) = (1/c) int_s^{L/2} v (zero ahead of the pulse)
// is their closed-form integral, so that v = -c du/ds (a wave moving towards +d). c is the phase
// speed: on a lattice, a short wavelength travels slower than the long-wave speed (set `speed`
// to the lattice's c sin(k a / 2) / (k a / 2) or a little of the pulse goes backwards).
// Displacements are applied after bonding.
void read_pulse(CaseNode root, dem::DemModel& model) {
  auto pulse = root.child_if("pulse");
  if (!pulse) return;
  const int g = group_of(*pulse, model);
  const Vec3 d0 = pulse->vec3("direction", Range::any(), "1");
  if (!(norm(d0) > 0.0)) pulse->fail("direction", "expected a non-zero direction");
  const Vec3 d = normalized(d0);
  const Vec3 center = pulse->vec3("center", Range::any(), "m");
  const double lambda = pulse->number("wavelength", Range::positive(), "m");
  const double A = pulse->number("amplitude", Range::any(), "m/s");
  const double c = pulse->number("speed", Range::positive(), "m/s");
  const long long cycles = pulse->has("cycles") ? pulse->integer("cycles", Range::at_least(1)) : 0;
  pulse->finish();
  const double k = 2.0 * std::numbers::pi / lambda;
  // v(s) = sum of a cos(m s) + b sin(m s) over (a, b, m), for |s| < L / 2.
  struct Term {
    double a, b, m;
  };
  std::vector<Term> terms;
  double L = lambda;
  if (cycles > 0) {
    L = static_cast<double>(cycles) * lambda;
    const double K = k / static_cast<double>(cycles);  // sin(ks) (1 + cos(Ks)) / 2 = sin(ks) / 2 + [sin((k+K)s) + sin((k-K)s)] / 4
    terms = {{0.0, 0.5 * A, k}, {0.0, 0.25 * A, k + K}, {0.0, 0.25 * A, k - K}};
  } else {
    terms = {{0.5 * A, 0.0, 0.0}, {0.5 * A, 0.0, k}};
  }
  // int of a cos(m t) + b sin(m t) from t = s to L / 2 (m = 0: a (L/2 - s)).
  const auto integral = [&](const Term& t, double s) {
    if (t.m == 0.0) return t.a * (0.5 * L - s);
    return (t.a * (std::sin(0.5 * t.m * L) - std::sin(t.m * s)) - t.b * (std::cos(0.5 * t.m * L) - std::cos(t.m * s))) / t.m;
  };
  for (std::uint32_t i : model.members(g)) {
    const double s = dot(model.particles.position[i] - center, d);
    const double sc = std::clamp(s, -0.5 * L, 0.5 * L);
    double v = 0.0, u = 0.0;
    for (const Term& t : terms) {
      if (std::abs(s) < 0.5 * L) v += t.a * std::cos(t.m * s) + t.b * std::sin(t.m * s);
      u += integral(t, sc) / c;
    }
    model.particles.velocity[i] += d * v;
    model.particles.position[i] += d * u;
  }
}

// A uniform strain to start from (patch tests): u = H x on every DE (its position moves, its
// bonds' reference stays) and every continuum node, H the displacement gradient by rows.
void read_initial_strain(CaseNode root, Scene& scene) {
  auto section = root.child_if("initial_strain");
  if (!section) return;
  const auto rows = section->vec3_list("gradient", Range::any(), "1");
  if (rows.size() != 3) section->fail("gradient", "expected three rows [[..], [..], [..]] of the displacement gradient");
  section->finish();
  const std::array<Vec3, 3> H{rows[0], rows[1], rows[2]};
  for (Vec3& x : scene.dem.particles.position) x += rows_times(H, x);
  if (scene.continuum) scene.continuum->set_affine_displacement(H);
  scene.initial_gradient = H;
}

void read_sensors(CaseNode root, Scene& scene) {
  static constexpr std::string_view types[] = {"force", "displacement", "velocity", "energy", "affine_deviation"};
  static constexpr std::string_view models[] = {"dem", "continuum"};
  const bool has_dem = scene.dem.particles.size() > 0;
  for (CaseNode s : root.list_or_empty("sensors")) {
    Sensor sensor;
    sensor.name = s.string("name");
    if (sensor.name.empty() || sensor.name.find_first_of(", \"") != std::string::npos)
      s.fail("name", "expected a non-empty name without commas, quotes or spaces");
    for (const Sensor& other : scene.sensors)
      if (other.name == sensor.name) s.fail("name", "sensor '" + sensor.name + "' is defined twice");
    const std::string type = s.choice("type", types);
    if (type == "affine_deviation") {
      // A patch test's measure: the whole scene against the initial_strain field.
      if (!scene.initial_gradient) s.fail("type", "an affine_deviation sensor needs an initial_strain section");
      sensor.kind = Sensor::Kind::affine_deviation;
      sensor.component = 0;
      s.finish();
      scene.sensors.push_back(sensor);
      continue;
    }
    sensor.kind = type == "force"          ? Sensor::Kind::force
                  : type == "displacement" ? Sensor::Kind::displacement
                  : type == "velocity"     ? Sensor::Kind::velocity
                                           : Sensor::Kind::energy;
    sensor.on_continuum = s.choice_or("on", has_dem ? "dem" : "continuum", models) == "continuum";
    if (sensor.on_continuum) {
      if (!scene.continuum) s.fail("on", "the case has no continuum");
      if (sensor.kind == Sensor::Kind::energy) s.fail("type", "energy sensors are for DEM groups");
      sensor.group_name = s.string("group");
      if (!scene.continuum->has_group(sensor.group_name))
        s.fail("group", "the continuum mesh has no physical group '" + sensor.group_name + "'");
    } else {
      if (!has_dem) s.fail("on", "the case has no DEM");
      sensor.group = group_of(s, scene.dem);
      sensor.group_name = s.string("group");
      if (sensor.kind == Sensor::Kind::force) scene.dem.watch_reaction(sensor.group);
    }
    if (sensor.kind == Sensor::Kind::energy) {
      sensor.component = 0;  // a scalar: one column
    } else {
      const std::string c = s.choice_or("component", "all", component_names);
      sensor.component = c == "all" ? -1 : c[0] - 'x';
    }
    s.finish();
    scene.sensors.push_back(sensor);
  }
}

void read_checks(CaseNode root, Scene& scene, const std::vector<std::string>& columns) {
  for (CaseNode c : root.list_or_empty("checks")) {
    Check check;
    check.column = c.string("column");
    if (std::find(columns.begin(), columns.end(), check.column) == columns.end()) {
      std::string known;
      for (const auto& k : columns) known += (known.empty() ? "" : ", ") + k;
      c.fail("column", "no series column '" + check.column + "' (columns: " + known + ")");
    }
    static constexpr std::string_view statistics[] = {"final", "max", "min", "final_over_initial"};
    if (c.has("crossing")) {
      check.kind = Check::Kind::crossing;
      check.threshold = c.number("crossing", Range::any(), "column unit");
    } else {
      const std::string statistic = c.choice_or("statistic", "final", statistics);
      check.kind = statistic == "final"  ? Check::Kind::final_value
                   : statistic == "max"  ? Check::Kind::maximum
                   : statistic == "min"  ? Check::Kind::minimum
                                         : Check::Kind::final_over_initial;
    }
    const char* unit = check.kind == Check::Kind::crossing ? "s" : "column unit";
    check.bounded = c.has("at_most") || c.has("at_least");
    if (check.bounded) {
      if (c.has("expected")) c.fail("expected", "give either expected and tolerance, or at_most / at_least");
      // Only the bounds given (an unbounded side has no number a case file could hold).
      if (c.has("at_most")) check.at_most = c.number("at_most", Range::any(), unit);
      if (c.has("at_least")) check.at_least = c.number("at_least", Range::any(), unit);
    } else {
      check.expected = c.number("expected", Range::any(), unit);
      check.tolerance = c.number("tolerance", Range::positive(), "1");
    }
    check.note = c.string_or("note", "");
    c.finish();
    scene.checks.push_back(check);
  }
}

// The output folder (--out, else output.dir, else results/<name>), checked now (unless
// options.check_output_dir is off, as for `check`), so that one that cannot be written is bad
// input before any work. Nothing is created here; the run creates it.
std::filesystem::path prepare_output_dir(std::optional<CaseNode> out, const std::string& name, const SceneOptions& options) {
  std::filesystem::path dir = out ? out->string_or("dir", "results/" + name) : "results/" + name;
  if (!options.out_dir.empty()) dir = options.out_dir;
  if (!options.check_output_dir) return dir;
  // The folder itself, or the nearest of its parents that exists, must be a folder we may write
  // in and enter; a parent we may not look into is a problem of its own.
  std::string problem;
  std::error_code ec;
  std::filesystem::path existing = std::filesystem::absolute(dir, ec);
  for (;;) {
    const auto status = std::filesystem::status(existing, ec);
    if (std::filesystem::exists(status)) break;
    if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory) {
      problem = "'" + existing.string() + "': " + ec.message();
      break;
    }
    if (!existing.has_parent_path() || existing == existing.parent_path()) break;
    existing = existing.parent_path();
  }
  if (problem.empty() && !std::filesystem::is_directory(existing, ec))
    problem = "'" + existing.string() + "' is not a folder";
  else if (problem.empty() && access(existing.c_str(), W_OK | X_OK) != 0)
    problem = "'" + existing.string() + "' is not writable (" + std::strerror(errno) + ")";
  if (!problem.empty()) {
    const std::string message = "cannot write the outputs to '" + dir.string() + "': " + problem;
    if (options.out_dir.empty() && out && out->has("dir")) out->fail("dir", message);
    throw InputError((options.out_dir.empty() ? "output folder" : "--out") + std::string(": ") + message);
  }
  return dir;
}

void read_output(std::optional<CaseNode> out, Scene& scene) {
  static constexpr std::string_view field_kinds[] = {"particles", "bonds", "continuum"};
  OutputPlan& plan = scene.output;
  plan.every = scene.end_time / 100.0;
  if (out) {
    plan.every = out->number_or("every", plan.every, Range::positive(), "s");
    for (const std::string& f : out->strings_or("fields", {})) {
      if (std::find(std::begin(field_kinds), std::end(field_kinds), f) == std::end(field_kinds))
        out->fail("fields", "unknown field set '" + f + "' (expected particles, bonds, continuum)");
      (f == "particles" ? plan.particle_fields : f == "bonds" ? plan.bond_fields : plan.continuum_fields) = true;
    }
    plan.fields_every = out->number_or("fields_every", plan.every, Range::positive(), "s");
    for (CaseNode p : out->list_or_empty("plots")) {
      PlotPlan plot;
      plot.file = p.string("file");
      const auto ext = plot.file.extension();
      if ((ext != ".png" && ext != ".svg" && ext != ".pdf") || plot.file.has_parent_path())
        p.fail("file", "expected a file name ending in .png, .svg or .pdf (written in the output folder)");
      plot.title = p.string_or("title", "");
      plot.x = p.string("x");
      plot.x_scale = p.number_or("x_scale", 1.0, Range::any(), "1");
      plot.x_label = p.string_or("x_label", plot.x);
      plot.y = p.strings("y");
      plot.y_scale = p.number_or("y_scale", 1.0, Range::any(), "1");
      plot.y_label = p.string_or("y_label", "");
      plot.y2 = p.strings_or("y2", {});
      plot.y2_scale = p.number_or("y2_scale", 1.0, Range::any(), "1");
      plot.y2_label = p.string_or("y2_label", "");
      p.finish();
      plan.plots.push_back(plot);
    }
    out->finish();
  }
}

}  // namespace

std::span<const SchemaSection> scene_schema() { return scene_sections; }

std::vector<std::string> series_columns(const Scene& scene) {
  std::vector<std::string> columns{"time", "step"};
  for (auto& c : sensor_columns(scene)) columns.push_back(c);
  columns.insert(columns.end(), std::begin(energy_columns), std::end(energy_columns));
  if (scene.continuum) columns.insert(columns.end(), {"C_kinetic", "C_strain"});
  if (scene.model->monitor()) columns.insert(columns.end(), std::begin(coupling_columns), std::end(coupling_columns));
  if (scene.dem.failure_enabled())
    for (const auto& set : scene.dem.bond_sets()) columns.push_back("broken_" + set->name);
  return columns;
}

std::vector<std::string> sensor_columns(const Scene& scene) {
  std::vector<std::string> out;
  for (const Sensor& s : scene.sensors) {
    if (s.component >= 0) {
      out.push_back(s.name);
    } else {
      for (const char* axis : {"_x", "_y", "_z"}) out.push_back(s.name + axis);
    }
  }
  return out;
}

Scene build_scene(const std::filesystem::path& case_file, const SceneOptions& options) {
  CaseFile file = CaseFile::load(case_file, options.overrides, &case_schema());
  CaseNode root = file.root();
  Scene scene;
  scene.case_file = case_file;
  scene.name = root.string_or("name", case_file.parent_path().filename().string());
  static constexpr std::string_view unit_systems[] = {"SI"};
  root.choice_or("units", "SI", unit_systems);
  scene.output.dir = prepare_output_dir(root.child_if("output"), scene.name, options);

  // The models first: the time section's defaults depend on them.
  std::optional<CaseNode> dem_node = root.child_if("dem");
  std::optional<CaseNode> continuum_node = root.child_if("continuum");
  if (!dem_node && !continuum_node) root.fail("dem", "a case needs a dem section, a continuum section, or both");
  std::optional<CaseNode> coupling = root.child_if("coupling");
  if (coupling && (!dem_node || !continuum_node))
    coupling->fail("overlap", "coupling needs both a dem and a continuum section");
  // The continuum first: a coupling's overlap cuts the DEM sample to its domain.
  if (continuum_node) scene.continuum = ContinuumPart::read(*continuum_node, coupling, options.petsc_options);
  dem::DemModel& model = scene.dem;
  if (dem_node) {
    std::vector<std::string> materials;
    if (dem_node->has("materials")) {
      for (const char* single : {"density", "bond"})
        if (dem_node->has(single))
          dem_node->fail(single, "give either dem.materials or dem.density and dem.bond, not both");
      read_sample(dem_node->child("sample"), scene, 1.0, options);
      materials = read_materials(*dem_node, model, default_bond_tolerance(scene));
    } else {
      const double density = dem_node->number("density", Range::positive(), "kg/m^3");
      read_sample(dem_node->child("sample"), scene, density, options);
      if (auto bond = dem_node->child_if("bond")) read_bonds(*bond, model, default_bond_tolerance(scene));
    }
    if (auto contact = dem_node->child_if("contact")) {
      double mean_radius = 0.0;
      for (double r : model.particles.radius) mean_radius += r;
      mean_radius /= double(model.particles.size());
      const double skin = contact->number_or("skin", 0.2 * mean_radius, Range::positive(), "m");
      model.set_contact(dem::make_contact_law(*contact), skin);
      contact->finish();
    }
    model.set_damping(dem_node->number_or("damping", 0.0, Range::non_negative(), "1/s"));
    if (auto failure = dem_node->child_if("failure")) read_failure(*failure, model, materials);
    dem_node->finish();
  }

  if (dem_node) {
    read_groups(root, model);
    read_initial(root, model);
    read_pulse(root, model);
  }
  read_initial_strain(root, scene);
  read_sensors(root, scene);
  if (dem_node) read_boundary(root, model);
  finalize_models(root, scene, coupling.has_value());

  const bool static_only = scene.static_only();
  std::optional<CaseNode> time = static_only ? root.child_if("time") : root.child("time");
  scene.end_time = time ? time->number("end", Range::positive(), "s") : 1.0;
  const std::optional<double> user_dt = time ? time->number_or_auto("dt", Range::positive(), "s") : std::nullopt;
  scene.safety = time ? time->number_or("safety", 0.3, Range::open_between(0.0, 1.0), "1") : 0.3;
  if (time) time->finish();

  // Coupled: the coupled system's step (the smaller of both, weighted); else each model's.
  scene.dt_critical = scene.model->critical_time_step();
  // A zero or NaN limit (a stiffness overflowing to inf, a zero mass) would give dt = 0 and a
  // run of no steps, or NaN everywhere.
  if (!static_only && !(scene.dt_critical > 0.0)) {
    std::ostringstream msg;
    msg << "the critical time step is " << scene.dt_critical
        << " s: a stiffness or a mass of the scene is out of range (check the moduli, densities and radii)";
    throw InputError(root.where() + ": " + msg.str());
  }
  if (static_only) {
    scene.dt = scene.end_time;  // one static solve
  } else if (user_dt) {
    if (*user_dt > scene.dt_critical) {
      std::ostringstream msg;
      msg << "time step " << *user_dt << " s is above the critical time step " << scene.dt_critical
          << " s (2/omega_max over bonds, contacts and the continuum); use dt <= " << scene.dt_critical << " or dt: auto";
      time->fail("dt", msg.str());
    }
    scene.dt = *user_dt;
  } else {
    if (!std::isfinite(scene.dt_critical))
      time->fail("dt", "the scene has no bond or contact stiffness, so dt: auto has no limit to scale; give dt in s");
    scene.dt = scene.safety * scene.dt_critical;
  }
  const double steps = std::ceil(scene.end_time / scene.dt - 1e-9);
  if (!(steps >= 1.0) || steps > 1e15) {
    std::ostringstream msg;
    if (steps >= 1.0)
      msg << "time.end / dt = " << steps << " steps (time.end " << scene.end_time << " s, dt " << scene.dt
          << " s): more than 1e15; raise dt or lower time.end";
    else
      msg << "time.end = " << scene.end_time << " s is not even 1e-9 of a time step (dt = " << scene.dt << " s): no step would run";
    time->fail("end", msg.str());
  }
  scene.steps = static_cast<long>(steps);
  read_output(root.child_if("output"), scene);
  std::vector<std::string> columns = sensor_columns(scene);
  columns.insert(columns.end(), {"E_kinetic", "E_bond", "E_contact", "W_external", "E_dissipated", "E_fracture", "E_total"});
  read_checks(root, scene, columns);
  // Plots name columns that this run writes.
  columns = series_columns(scene);
  for (const PlotPlan& plot : scene.output.plots) {
    std::vector<std::string> used{plot.x};
    used.insert(used.end(), plot.y.begin(), plot.y.end());
    used.insert(used.end(), plot.y2.begin(), plot.y2.end());
    for (const auto& c : used)
      if (std::find(columns.begin(), columns.end(), c) == columns.end())
        throw InputError(root.where() + ": output.plots: no series column '" + c + "' for " + plot.file.string());
  }
  root.finish();
  scene.resolved_case = file.resolved_yaml();
  return scene;
}

}  // namespace arlequin::app
