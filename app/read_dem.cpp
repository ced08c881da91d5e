// SPDX-License-Identifier: GPL-3.0-or-later
// The dem section of a case: sample, bonds, materials, contact, damping, failure (and their keys).
#include "app/scene_readers.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "common/atomic_file.hpp"
#include "common/case_file.hpp"
#include "common/error.hpp"
#include "common/memory.hpp"
#include "common/region.hpp"
#include "common/schema.hpp"
#include "dem/bonds/bond_set.hpp"
#include "dem/bonds/cohesive_contact.hpp"
#include "dem/contacts/contact_law.hpp"
#include "dem/sample_file.hpp"
#include "dem/samples.hpp"
#include "dem/weave.hpp"

namespace arlequin::app {
namespace {

constexpr KeyDoc dem_keys[] = {
    {"sample", KeyType::section, "", {}, "", "how the DEs are placed (lattice, chain, particles, packing)"},
    {"density", KeyType::number, "kg/m^3", Range::positive(), "(none)",
     "DE density, with one bond law for all (else materials); with a weave, of the listed DEs that give none"},
    {"bond", KeyType::section, "", {}, "(none)", "bonds between every two DEs that touch, one law for all"},
    {"materials", KeyType::names, "", {}, "(none)", "materials by name, each with its density, region and bond law"},
    {"interface", KeyType::section, "", {}, "(none)", "the bond law between DEs of two different materials"},
    {"bond_tolerance", KeyType::number, "1", Range::between(0, 1), "(the packing's, else 0.01)", "gap, over the mean radius, below which two DEs of materials bond"},
    {"contact", KeyType::section, "", {}, "(none)", "contact between DEs that are not bonded (a neighbour search)"},
    {"damping", KeyType::number, "1/s", Range::non_negative(), "0", "viscous damping of DE velocities, c in dv/dt = ... - c v"},
    {"gravity", KeyType::vec3, "m/s^2", {}, "[0, 0, 0]", "uniform gravity: a body force m g on every DE (its work in W_external)"},
    {"failure", KeyType::section, "", {}, "(none)", "failure criteria beyond the bond laws' own (RDEF)"},
};
constexpr KeyDoc sample_keys[] = {
    {"build", KeyType::choice, "", {}, "", "how the DEs are made", "lattice | chain | particles | packing | weave"},
    {"radius", KeyType::number, "m", Range::positive(), "(none)", "DE radius (lattice, chain); a packing gives a distribution instead"},
    {"spacing", KeyType::number, "m", Range::positive(), "(2 radius)", "centre distance of neighbours (lattice, chain)"},
    {"origin", KeyType::vec3, "m", {}, "[0, 0, 0]", "centre of the lattice's first DE"},
    {"counts", KeyType::numbers, "1", Range::at_least(1), "", "DEs along x, y, z (lattice)"},
    {"start", KeyType::vec3, "m", {}, "[0, 0, 0]", "centre of the chain's first DE"},
    {"direction", KeyType::vec3, "1", {}, "[1, 0, 0]", "direction of the chain"},
    {"count", KeyType::integer, "", Range::at_least(1), "", "DEs in the chain"},
    {"particles", KeyType::list, "", {}, "", "the DEs one by one (particles)"},
    {"table", KeyType::file, "", {}, "(none)",
     "particles: a CSV of the DEs, header x,y,z,radius[,vx,vy,vz], one DE per row (m, m/s), relative to the case"},
    {"region", KeyType::section, "", {}, "", "the region the packing fills (a region: box, cylinder, sphere)"},
    {"compaction", KeyType::number, "1", Range::open_between(0, 0.7), "0.63", "target solid fraction of the packing"},
    {"min_coordination", KeyType::number, "1", Range::non_negative(), "6", "mean number of bonded neighbours the packing must reach"},
    {"seed", KeyType::integer, "", Range::non_negative(), "1", "random seed of the packing"},
    {"bond_tolerance", KeyType::number, "1", Range::between(0, 0.5), "0.03", "gap, over the mean radius, that counts as contact in the packing"},
    {"file", KeyType::string, "", {}, "(results/<name>/sample.h5)", "where the packing is cached (HDF5), relative to the case"},
    {"keep", KeyType::section, "", {}, "(every DE)",
     "packing: only the DEs whose centre lies in this region are created (a piece of a specimen, e.g. for a virtual test; the cache holds the whole packing)"},
    {"size", KeyType::numbers, "m", Range::positive(), "", "weave: the fabric's extent [along x (weft), along y (warp)]"},
    {"weft_layers", KeyType::integer, "", Range::at_least(2), "3", "weave: layers of weft yarns"},
    {"weft_spacing", KeyType::number, "m", Range::positive(), "", "weave: centre distance of the weft columns (along y)"},
    {"warp_spacing", KeyType::number, "m", Range::positive(), "", "weave: centre distance of the stuffer warps (along x); a binder runs midway"},
    {"yarn_width", KeyType::number, "m", Range::positive(), "", "weave: width of a yarn's cross-section"},
    {"yarn_thickness", KeyType::number, "m", Range::positive(), "", "weave: thickness of a yarn's cross-section (2 R chains_through)"},
    {"chains", KeyType::numbers, "1", Range::at_least(1), "[1, 1]", "weave: parallel DE chains of a yarn [across its width, through its thickness] (n_p their product)"},
    {"crimp", KeyType::number, "1", Range::positive(), "(the smallest that clears the weft)", "weave: the binders' crimp, path length over fabric length - 1"},
    {"clamp_width", KeyType::number, "m", Range::non_negative(), "0", "weave: width of the border whose DEs form the group 'edges'"},
    {"yarn", KeyType::section, "", {}, "", "weave: the yarn's material and spring law (seed Eqs. 6-8)"},
};
constexpr KeyDoc yarn_keys[] = {
    {"density", KeyType::number, "kg/m^3", Range::positive(), "", "yarn density over its section S (a DE's mass: rho S L_y / DEs of the yarn)"},
    {"modulus", KeyType::number, "Pa", Range::positive(), "", "yarn modulus E: a spring of rest length L0 has K = E S / (n_p L0)"},
    {"section", KeyType::number, "m^2", Range::positive(), "(pi yarn_width yarn_thickness / 4)", "the yarn's section S"},
    {"failure_strain", KeyType::number, "1", Range::non_negative(), "0", "elongation at which a spring breaks; 0: never"},
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
    {"density", KeyType::number, "kg/m^3", Range::positive(), "(dem.density)", "density of this DE (an impactor of another material)"},
};
constexpr KeyDoc bond_law_key{"law", KeyType::choice, "", {}, "", "the bond law (arlequin laws); its own keys follow in 'bond (law: ...)'",
                              "beam | spring | cohesive_bilinear"};
constexpr KeyDoc dem_bond_keys[] = {
    bond_law_key,
    {"tolerance", KeyType::number, "1", Range::between(0, 1), "(the packing's, else 0.01)", "gap, over the mean radius, below which two DEs bond"},
};
constexpr KeyDoc material_bond_keys[] = {bond_law_key};
constexpr KeyDoc contact_keys[] = {
    {"law", KeyType::choice, "", {}, "", "the contact law (arlequin laws); its own keys follow in 'contact (law: ...)'", "penalty"},
    {"skin", KeyType::number, "m", Range::positive(), "(0.2 x the mean radius)", "neighbour list margin: rebuilt once the two largest displacements since the last build add up to it"},
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
constexpr SchemaSection dem_sections[] = {
    {"dem", "the discrete elements", dem_keys},
    {"dem.sample", "how the DEs are placed", sample_keys},
    {"dem.sample.radius", "radius distribution of a packing (truncated Gaussian)", radius_distribution_keys},
    {"dem.sample.yarn", "a weave's yarn", yarn_keys},
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
};

// A lattice, chain or packing of `des` DEs that cannot fit in this machine's memory is refused
// at `key` before it is built: a DE's state takes about 200 B (dem/particles.hpp, structure of
// arrays) and a lattice DE's three bonds at least 100 B each, so 500 B per DE is a floor.
void refuse_beyond_memory(CaseNode& sample, const char* key, double des) {
  constexpr double kBytesPerDe = 500.0;
  if (const std::string beyond = beyond_memory(des * kBytesPerDe, "about 500 B per DE with its bonds"); !beyond.empty()) {
    char count[32];
    std::snprintf(count, sizeof count, "%.3g", des);
    sample.fail(key, std::string("makes ") + count + " DEs, " + beyond);
  }
}

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
  try {
    refuse_beyond_memory(sample, "region", dem::estimated_count(spec));
  } catch (const std::invalid_argument& e) {
    sample.fail("region", e.what());
  }
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
  if (options.write_sample_cache) dem::save_sample(file, p, spec, scene.sample->report);
}

// build: particles, table: FILE.csv. Header x,y,z,radius with optional vx,vy,vz (in that
// order); each further line one DE. InputError at FILE:LINE for a row that is not those numbers.
void read_particle_table(CaseNode& sample, Scene& scene, double density) {
  const std::filesystem::path file = sample.existing_file("table");
  const std::string text = read_text_file(file);
  dem::ParticleSet& p = scene.dem.particles;
  std::size_t line_no = 0, columns = 0;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    std::string_view line(text.data() + at, end - at);
    at = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty()) continue;
    const auto where = [&] { return file.string() + ":" + std::to_string(line_no) + ": "; };  // for errors only
    if (columns == 0) {
      columns = line == "x,y,z,radius" ? 4 : line == "x,y,z,radius,vx,vy,vz" ? 7 : 0;
      if (columns == 0)
        throw InputError(where() + "expected the header x,y,z,radius or x,y,z,radius,vx,vy,vz (dem.sample.table)");
      continue;
    }
    double v[7];
    const char* c = line.data();
    const char* const stop = line.data() + line.size();
    for (std::size_t k = 0; k < columns; ++k) {
      const auto [next, error] = std::from_chars(c, stop, v[k]);
      const bool last = k + 1 == columns;
      if (error != std::errc() || (last ? next != stop : (next == stop || *next != ',')) || !std::isfinite(v[k]))
        throw InputError(where() + "expected " + std::to_string(columns) + " comma-separated numbers (dem.sample.table)");
      c = next + 1;
    }
    if (!(v[3] > 0.0)) throw InputError(where() + "a radius must be > 0 m (dem.sample.table)");
    const Vec3 x{v[0], v[1], v[2]};
    if (scene.continuum && !scene.continuum->in_dem_domain(x))
      throw InputError(where() + "this DE lies beyond the coupling overlap, in the pure-continuum zone (dem.sample.table)");
    const std::size_t i = p.add(x, v[3], density);
    if (columns == 7) p.velocity[i] = {v[4], v[5], v[6]};
  }
  if (columns == 0 || p.size() == 0) throw InputError(file.string() + ": no DE in the table (dem.sample.table)");
}

constexpr std::string_view builders[] = {"lattice", "chain", "particles", "packing", "weave"};

// build: weave (dem/weave.hpp): the DEs, their springs and the groups of a 3D interlock.
void read_weave(CaseNode& sample, Scene& scene) {
  dem::WeaveSpec spec;
  const auto size = sample.numbers("size", Range::positive(), "m");
  if (size.size() != 2) sample.fail("size", "expected the fabric's extent [along x, along y]");
  spec.length_x = size[0], spec.length_y = size[1];
  spec.weft_layers = int(sample.integer_or("weft_layers", 3, Range::at_least(2)));
  spec.weft_spacing = sample.number("weft_spacing", Range::positive(), "m");
  spec.warp_spacing = sample.number("warp_spacing", Range::positive(), "m");
  spec.yarn_width = sample.number("yarn_width", Range::positive(), "m");
  spec.yarn_thickness = sample.number("yarn_thickness", Range::positive(), "m");
  const auto chains = sample.has("chains") ? sample.numbers("chains", Range::at_least(1), "1") : std::vector<double>{1.0, 1.0};
  if (chains.size() != 2 || chains[0] != std::floor(chains[0]) || chains[1] != std::floor(chains[1]))
    sample.fail("chains", "expected two whole numbers [across the width, through the thickness]");
  spec.chains_across = int(chains[0]), spec.chains_through = int(chains[1]);
  spec.crimp = sample.has("crimp") ? sample.number("crimp", Range::positive(), "1") : 0.0;
  spec.clamp_width = sample.number_or("clamp_width", 0.0, Range::non_negative(), "m");
  CaseNode yarn = sample.child("yarn");
  spec.density = yarn.number("density", Range::positive(), "kg/m^3");
  spec.modulus = yarn.number("modulus", Range::positive(), "Pa");
  spec.section = yarn.has("section") ? yarn.number("section", Range::positive(), "m^2")
                                     : std::numbers::pi * spec.yarn_width * spec.yarn_thickness / 4.0;
  spec.failure_strain = yarn.number_or("failure_strain", 0.0, Range::non_negative(), "1");
  yarn.finish();
  // A rough count first (two yarn families crossing the fabric per column), against memory.
  refuse_beyond_memory(sample, "size",
                       spec.chains_across * spec.chains_through * spec.weft_layers *
                           (spec.length_x / spec.weft_spacing * spec.length_y + spec.length_y / spec.warp_spacing * spec.length_x) /
                           spec.yarn_thickness * spec.chains_through);
  try {
    // Coupled: the DEM patch is the weave's part in the DEM domain (its yarns end in the overlap).
    std::function<bool(const Vec3&)> keep;
    if (scene.continuum) keep = [&scene](const Vec3& x) { return scene.continuum->in_dem_domain(x); };
    scene.weave = dem::build_weave(scene.dem, spec, keep);
  } catch (const dem::WeaveError& e) {
    sample.fail(e.field(), e.what());
  }
}

// `density`: of the DEs built or listed (NaN with a weave and no dem.density: each listed DE
// gives its own).
void read_sample(CaseNode sample, Scene& scene, double density, const SceneOptions& options) {
  dem::ParticleSet& p = scene.dem.particles;
  const std::string build = sample.choice("build", builders);
  if (build == "weave") {
    read_weave(sample, scene);
  } else if (build == "packing") {
    read_packing(sample, scene, density, options);
    // A piece of a specimen's packing, cut from the whole one, keeps the specimen's own surfaces
    // and inner layers where a packing of the piece alone would have surfaces at its cuts.
    if (auto keep = sample.child_if("keep")) {
      const Region region = Region::read(*keep);
      keep->finish();
      p.keep_only([&](std::size_t i) { return region.contains(p.position[i]); });
      if (p.size() == 0) sample.fail("keep", "no DE of the packing has its centre in this region");
    }
  } else if (build == "lattice") {
    const Vec3 origin = sample.vec3_or("origin", {}, Range::any(), "m");
    const auto counts = sample.numbers("counts", Range::at_least(1), "1");
    if (counts.size() != 3) sample.fail("counts", "expected three DE counts [nx, ny, nz]");
    for (double c : counts)
      if (c != std::floor(c)) sample.fail("counts", "expected whole numbers");
    refuse_beyond_memory(sample, "counts", counts[0] * counts[1] * counts[2]);
    const double radius = sample.number("radius", Range::positive(), "m");
    const double spacing = sample.number_or("spacing", 2.0 * radius, Range::positive(), "m");
    dem::build_lattice(p, origin, {int(counts[0]), int(counts[1]), int(counts[2])}, spacing, radius, density);
  } else if (build == "chain") {
    const Vec3 start = sample.vec3_or("start", {}, Range::any(), "m");
    const Vec3 direction = sample.vec3_or("direction", {1, 0, 0}, Range::any(), "1");
    if (!(norm(direction) > 0.0)) sample.fail("direction", "expected a non-zero direction vector");
    const auto count = sample.integer("count", Range::at_least(1));
    refuse_beyond_memory(sample, "count", double(count));
    const double radius = sample.number("radius", Range::positive(), "m");
    const double spacing = sample.number_or("spacing", 2.0 * radius, Range::positive(), "m");
    dem::build_chain(p, start, normalized(direction), int(count), spacing, radius, density);
  }
  // Coupled: the built DEs beyond the overlap (in the pure-continuum zone) are not created (a
  // weave's are not built).
  if (scene.weave)
    scene.des_not_created = scene.weave->des_not_kept;
  else if (scene.continuum)
    scene.des_not_created = p.keep_only([&](std::size_t i) { return scene.continuum->in_dem_domain(p.position[i]); });
  // Explicit DEs (an impactor, a two-body test), after the built ones; the only ones for
  // build: particles.
  // A large set of DEs comes as a table (a YAML list of 500 000 DEs takes the YAML parser
  // minutes): read before the list, which may add more.
  const bool table = build == "particles" && sample.has("table");
  if (table) read_particle_table(sample, scene, density);
  const auto listed = build == "particles" && !table ? sample.list("particles") : sample.list_or_empty("particles");
  const std::size_t built = p.size();
  for (CaseNode item : listed) {
    const Vec3 x = item.vec3("position", Range::any(), "m");
    if (scene.continuum && !scene.continuum->in_dem_domain(x))
      item.fail("position", "this DE lies beyond the coupling overlap, in the pure-continuum zone");
    const double r = item.number("radius", Range::positive(), "m");
    // An impactor that starts inside a fabric would be shot out by the contact at once.
    if (scene.weave) {
      for (std::size_t j = 0; j < built; ++j)
        if (norm(p.position[j] - x) < r + p.radius[j]) {
          char where[160];
          std::snprintf(where, sizeof where, "this DE starts inside the fabric: it overlaps the yarn DE at (%.4g, %.4g, %.4g) mm",
                        p.position[j].x * 1e3, p.position[j].y * 1e3, p.position[j].z * 1e3);
          item.fail("position", where);
        }
    }
    const double own = item.has("density") ? item.number("density", Range::positive(), "kg/m^3") : density;
    if (std::isnan(own)) item.fail("density", "expected this DE's density (there is no dem.density to fall back on)");
    const std::size_t i = p.add(x, r, own);
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

// A cohesive interface's `area` is the nominal area its links' sections add up to (d26). Given
// for a whole interface where only part of it holds DEs (a coupled DEM band), it would make
// every link that many times too stiff and too strong, silently: refused when it is not within
// 10 % of the area the links cover (CohesiveContactSet::covered_area, which the cases' `area`
// exceeds by 0.9 to 2.6 %, docs/decisions.md#d55).
void check_interface_area(const dem::BondSet& interface, const dem::ParticleSet& p, CaseNode& bond) {
  const auto* cohesive = dynamic_cast<const dem::CohesiveContactSet*>(&interface);
  if (!cohesive || !(cohesive->parameters().area > 0.0)) return;
  const double covered = cohesive->covered_area(p), ratio = cohesive->parameters().area / covered;
  if (!(covered > 0.0) || std::abs(std::log(ratio)) <= std::log(1.1)) return;
  char text[320];
  std::snprintf(text, sizeof text,
                "%.4g m^2 is %.3g times the %.4g m^2 its %zu links cover (their contact points' hull, widened by half "
                "their spacing): expected the nominal area of the interface where there are DEs (a DEM band's share of it)",
                cohesive->parameters().area, ratio, covered, interface.size());
  bond.fail("area", text);
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
  std::vector<std::vector<std::uint32_t>> members(list.size());
  for (std::size_t i = 0; i < p.size(); ++i) members[material_of[i]].push_back(static_cast<std::uint32_t>(i));
  for (std::size_t m = 0; m < list.size(); ++m) model.add_group(list[m].name, std::move(members[m]));

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
  std::optional<CaseNode> interface_bond;
  if (auto section = dem_node.child_if("interface")) {
    interface_bond = section->child("bond");
    interface = &model.add_bond_set(dem::make_bond_set(*interface_bond));
    interface->name = "interface";
    interface_bond->finish();
    section->finish();
  }
  for (auto [i, j] : dem::close_pairs(p, tolerance)) {
    const int a = material_of[i], b = material_of[j];
    dem::BondSet* set = a == b ? set_of[a] : interface;
    if (set) set->add(i, j, p);
  }
  if (interface) {
    // An interface law that joins nothing, or whose links all start failed, is a mistake in the
    // materials' regions or in the pre-crack, not a model.
    if (interface->size() == 0)
      interface_bond->fail("law", "no pair of DEs of two different materials is close enough to join: the materials' regions "
                                  "do not meet (or raise dem.bond_tolerance)");
    const auto broken = interface->broken();
    if (std::count(broken.begin(), broken.end(), std::uint8_t{1}) == std::ptrdiff_t(broken.size()))
      interface_bond->fail("precrack", "the pre-crack holds every one of the interface's " + std::to_string(broken.size()) +
                                           " links: it is as long as the specimen, nothing is left to crack");
    check_interface_area(*interface, p, *interface_bond);
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

}  // namespace

std::span<const SchemaSection> dem_schema() { return dem_sections; }

// The dem section: the sample, its bonds (one law, or materials and their interface), contact,
// damping and failure, into scene.dem (not finalized).
void read_dem(CaseNode dem_node, Scene& scene, const SceneOptions& options) {
  dem::DemModel& model = scene.dem;
  std::vector<std::string> materials;
  CaseNode sample = dem_node.child("sample");
  if (sample.choice("build", builders) == "weave") {
    for (const char* own : {"materials", "bond"})
      if (dem_node.has(own)) dem_node.fail(own, "a weave makes its own springs (dem.sample.yarn); remove this key");
    const double density = dem_node.has("density") ? dem_node.number("density", Range::positive(), "kg/m^3") : NAN;
    read_sample(sample, scene, density, options);
  } else if (dem_node.has("materials")) {
    for (const char* single : {"density", "bond"})
      if (dem_node.has(single))
        dem_node.fail(single, "give either dem.materials or dem.density and dem.bond, not both");
    read_sample(dem_node.child("sample"), scene, 1.0, options);
    materials = read_materials(dem_node, model, default_bond_tolerance(scene));
  } else {
    const double density = dem_node.number("density", Range::positive(), "kg/m^3");
    read_sample(dem_node.child("sample"), scene, density, options);
    if (auto bond = dem_node.child_if("bond")) read_bonds(*bond, model, default_bond_tolerance(scene));
  }
  if (auto contact = dem_node.child_if("contact")) {
    double mean_radius = 0.0;
    for (double r : model.particles.radius) mean_radius += r;
    mean_radius /= double(model.particles.size());
    const double skin = contact->number_or("skin", 0.2 * mean_radius, Range::positive(), "m");
    dem::ContactDefaults defaults;
    if (scene.weave) defaults.stiffness = scene.weave->spring_stiffness;
    model.set_contact(dem::make_contact_law(*contact, defaults), skin);
    contact->finish();
  }
  model.set_damping(dem_node.number_or("damping", 0.0, Range::non_negative(), "1/s"));
  model.set_gravity(dem_node.vec3_or("gravity", {}, Range::any(), "m/s^2"));
  if (auto failure = dem_node.child_if("failure")) read_failure(*failure, model, materials);
  dem_node.finish();
}

}  // namespace arlequin::app
