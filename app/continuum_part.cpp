// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/continuum_part.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <vector>

#include "common/case_file.hpp"
#include "common/error.hpp"
#include "common/fields_writer.hpp"
#include "common/json.hpp"
#include "common/rise.hpp"
#include "continuum/continuum_solver.hpp"
#include "continuum/registry.hpp"
#include "coupling/coupled_model.hpp"
#include "common/region.hpp"

namespace arlequin::app {
namespace {

// ---- The schema of continuum: and coupling: (common/schema.hpp) ---------------------------

constexpr KeyDoc continuum_keys[] = {
    {"solver", KeyType::choice, "", {}, "", "finite elements or natural neighbours; swapping them is this one key", "fe | nem"},
    {"mesh", KeyType::section, "", {}, "", "the gmsh mesh"},
    {"material", KeyType::section, "", {}, "", "the elastic material"},
    {"analysis", KeyType::choice, "", {}, "explicit", "explicit dynamics, or one static solve", "explicit | static"},
    {"kinematics", KeyType::choice, "", {}, "small",
     "small strains and rotations, or finite: total Lagrangian, rotations of any size (explicit only)", "small | finite"},
    {"shape_functions", KeyType::choice, "", {}, "sibson", "nem: natural-neighbour interpolant", "sibson | laplace"},
    {"stabilization", KeyType::number, "1", Range::positive(), "1", "nem: weight of the SCNI stabilisation term"},
    {"petsc_options", KeyType::string, "", {}, "", "PETSc options of the static solve (e.g. -ksp_type cg -pc_type gamg)"},
    {"damping", KeyType::number, "1/s", Range::non_negative(), "0",
     "explicit: viscous damping, force -c m v on the free dofs (as dem.damping); it lowers the critical step"},
    {"boundary", KeyType::list, "", {}, "(none)", "boundary conditions on groups of mesh nodes"},
};
constexpr KeyDoc mesh_keys[] = {
    {"file", KeyType::file, "", {}, "", "a gmsh .geo (meshed at load) or .msh, relative to the case"},
    {"size", KeyType::number, "m", Range::non_negative(), "0", "element size for a .geo; 0: the file's own"},
    {"order", KeyType::integer, "", Range::between(1, 2), "1", "element order: P1 or P2 tetrahedra"},
    {"join", KeyType::section, "", {}, "(none)",
     "a region (box, cylinder, sphere, half_space) where the mesh's coincident nodes become one: bodies meshed apart are one body there"},
};
constexpr KeyDoc material_keys[] = {
    {"model", KeyType::choice, "", {}, "isotropic", "elastic model", "isotropic | transversely_isotropic | orthotropic"},
    {"density", KeyType::number, "kg/m^3", Range::positive(), "", "density"},
    {"inertia", KeyType::vec3, "1", {0.0, 1.0, true, false}, "[1, 1, 1]",
     "share of the mass a motion along x, y, z carries, each in (0, 1] (a dry weave: each yarn family's along its axis)"},
    {"E", KeyType::number, "Pa", Range::positive(), "", "isotropic: Young's modulus"},
    {"nu", KeyType::number, "1", Range::open_between(-1, 0.5), "", "isotropic: Poisson's ratio"},
    {"E_L", KeyType::number, "Pa", Range::positive(), "", "transversely isotropic: modulus along the axis"},
    {"E_T", KeyType::number, "Pa", Range::positive(), "", "transversely isotropic: modulus across the axis"},
    {"nu_LT", KeyType::number, "1", Range::open_between(-1, 0.5), "", "transversely isotropic: Poisson's ratio, axial load"},
    {"nu_TT", KeyType::number, "1", Range::open_between(-1, 1), "", "transversely isotropic: Poisson's ratio in the transverse plane"},
    {"G_LT", KeyType::number, "Pa", Range::positive(), "", "transversely isotropic: axial shear modulus"},
    {"axis", KeyType::vec3, "1", {}, "", "transversely isotropic: the axis (normalised)"},
    {"E_x", KeyType::number, "Pa", Range::positive(), "", "orthotropic: Young's modulus along x (likewise E_y, E_z)"},
    {"E_y", KeyType::number, "Pa", Range::positive(), "", "orthotropic: Young's modulus along y"},
    {"E_z", KeyType::number, "Pa", Range::positive(), "", "orthotropic: Young's modulus along z"},
    {"G_xy", KeyType::number, "Pa", Range::positive(), "", "orthotropic: shear modulus in the x-y plane"},
    {"G_xz", KeyType::number, "Pa", Range::positive(), "", "orthotropic: shear modulus in the x-z plane"},
    {"G_yz", KeyType::number, "Pa", Range::positive(), "", "orthotropic: shear modulus in the y-z plane"},
    {"nu_xy", KeyType::number, "1", Range::open_between(-1, 1), "0", "orthotropic: -eps_y / eps_x under stress along x"},
    {"nu_xz", KeyType::number, "1", Range::open_between(-1, 1), "0", "orthotropic: -eps_z / eps_x under stress along x"},
    {"nu_yz", KeyType::number, "1", Range::open_between(-1, 1), "0", "orthotropic: -eps_z / eps_y under stress along y"},
};
constexpr KeyDoc continuum_boundary_keys[] = {
    {"group", KeyType::string, "", {}, "", "a physical group of the mesh"},
    {"type", KeyType::choice, "", {}, "", "what it imposes", "fixed | displacement | velocity | traction"},
    {"value", KeyType::vec3, "(m, m/s or Pa by type)", {}, "", "the imposed displacement, velocity or traction"},
    {"components", KeyType::strings, "", {}, "(x, y, z)", "the components it acts on"},
    {"rise", KeyType::number, "s", Range::non_negative(), "0", "velocity: time over which it rises from 0, as (1 - cos(pi t / rise)) / 2"},
    {"duration", KeyType::number, "s", Range::positive(), "inf", "velocity: time after which it stops"},
};
constexpr KeyDoc coupling_keys[] = {
    {"overlap", KeyType::section, "", {}, "", "the overlap: a region (box or cylinder, with axis and dem_side), a shell or a band"},
    {"weight", KeyType::choice, "", {}, "linear", "partition-of-unity weight across the overlap", "linear | cubic | constant"},
    {"constant_value", KeyType::number, "1", Range::open_between(0, 1), "0.5", "the DEM's weight with weight: constant"},
    {"mass_floor", KeyType::number, "1", Range::open_between(0, 1), "0.05", "least weight on a mass (keeps the critical step finite)"},
    {"mediator", KeyType::choice, "", {}, "coarse", "multiplier space: the overlap's nodes, or one per coupled DE", "coarse | fine"},
    {"type", KeyType::choice, "", {}, "l2", "coupling operator: velocities, or velocities and their gradients", "l2 | h1"},
    {"ties", KeyType::list, "", {}, "(all DEs, x y z)", "DE groups the continuum holds along some components only (fine mediator, l2)"},
    {"length", KeyType::number, "m", Range::positive(), "", "h1: the length weighting the gradient term"},
    {"quadrature", KeyType::choice, "", {}, "plain", "consistent: the continuum's overlap weights corrected against the DE cloud",
     "plain | consistent"},
    {"solver", KeyType::choice, "", {}, "petsc", "the multiplier solve: PETSc (options below) or our sparse LDL^T", "petsc | direct"},
    {"petsc_options", KeyType::string, "", {}, "", "solver: petsc: PETSc options of the multiplier system (prefix coupling_)"},
    {"continuum_substeps", KeyType::integer_or_auto, "", Range::between(1, 1000), "1",
     "the continuum's internal force once every this many steps, as two impulses (multiple time stepping); "
     "auto: the most steps whose sum stays within the continuum's critical step"},
    {"on_damage_in_overlap", KeyType::choice, "", {}, "stop",
     "a bond the coupling weights (weight < 1) breaks: stop the run, say so once and go on, or hold such bonds intact "
     "(say so once)", "stop | warn | hold"},
};
constexpr KeyDoc overlap_keys[] = {
    {"shell", KeyType::section, "", {}, "(none)", "the space between two boxes, the DEM inside (instead of a region)"},
    {"shells", KeyType::list, "", {}, "(none)",
     "a union of shells, the DEM inside any inner box (a cross of bands; instead of a region; at most 4)"},
    {"band", KeyType::section, "", {}, "(none)", "a DEM band through a continuum, the overlap on its faces (instead of a region)"},
    {"axis", KeyType::choice, "", {}, "", "box: the axis across the overlap", "x | y | z"},
    {"dem_side", KeyType::choice, "", {}, "", "which side of the overlap is the pure-DEM zone",
     "(box: lower | upper; cylinder: base | top)"},
};
constexpr KeyDoc shell_keys[] = {
    {"inner", KeyType::vec3_list, "m", {}, "", "the inner box (pure DEM inside), two corners"},
    {"outer", KeyType::vec3_list, "m", {}, "", "the outer box (pure continuum outside), two corners"},
};
constexpr KeyDoc tie_keys[] = {
    {"group", KeyType::string, "", {}, "", "a DE group (a weave's: weft, stuffer, binder)"},
    {"components", KeyType::strings, "", {}, "", "the components the continuum holds its overlap DEs along; the others are free"},
};
constexpr KeyDoc band_keys[] = {
    {"axis", KeyType::choice, "", {}, "", "the direction across the band", "x | y | z"},
    {"center", KeyType::number, "m", Range::any(), "", "the band's mid-plane, along axis"},
    {"half_thickness", KeyType::number, "m", Range::positive(), "", "the DEM (overlap included) within this of the mid-plane"},
    {"width", KeyType::number, "m", Range::positive(), "", "the overlap's width on each face, below half_thickness"},
    {"along", KeyType::choice, "", {}, "", "the band's direction", "x | y | z"},
    {"from", KeyType::number, "m", Range::any(), "", "where the band starts along it (the overlap also ramps there)"},
    {"to", KeyType::number, "m", Range::any(), "", "where it ends (the overlap ramps there too; past a body's end by width or more, a free end)"},
    {"follow", KeyType::section, "", {}, "(none)", "the band moves along to keep the DEM interface's crack inside it (docs/theory.md#moving-zone)"},
};
constexpr KeyDoc follow_keys[] = {
    {"margin", KeyType::number, "m", Range::positive(), "", "the band moves when the interface's damage front comes within this of its to"},
    {"ahead", KeyType::number, "m", Range::positive(), "", "its new to: this beyond the damage front (at most until; more than margin)"},
    {"behind", KeyType::number, "m", Range::positive(), "(from stays)", "its new from: this behind the crack tip (never back; moving it disturbs the run, docs/decisions.md#d56)"},
    {"until", KeyType::number, "m", Range::any(), "", "the furthest to: the band's to with the whole interface in it"},
    {"settle_time", KeyType::number, "s", Range::non_negative(), "0", "after a move of from: how long the DEs around the new start are kinetically damped (0: not; measured worse than relax_steps alone)"},
    {"settle_length", KeyType::number, "m", Range::positive(), "0.006", "after a move of from: the damped DEs reach this beyond the new from"},
    {"relax_steps", KeyType::integer, "", Range::between(0, 1000000), "4000", "after a move of from: pseudo-time steps of the coupled state's dynamic relaxation toward the accelerations before the move (0: none)"},
};
constexpr SchemaSection continuum_sections[] = {
    {"continuum", "a continuum model", continuum_keys},
    {"continuum.mesh", "its mesh", mesh_keys},
    {"continuum.material", "its material", material_keys},
    {"continuum.boundary[]", "a boundary condition on the continuum", continuum_boundary_keys},
    {"coupling", "Arlequin coupling of the DEM zone and the continuum", coupling_keys},
    {"coupling.overlap", "the overlap (also the keys of region)", overlap_keys},
    {"coupling.ties[]", "a DE group tied along some components only", tie_keys},
    {"coupling.overlap.shell", "a shell overlap", shell_keys},
    {"coupling.overlap.shells[]", "a shell of a union of shells", shell_keys},
    {"coupling.overlap.band", "a band overlap: the shell of a slab, DEM inside, across all of the third direction", band_keys},
    {"coupling.overlap.band.follow", "a band that follows a crack: it moves, the scene built again around it", follow_keys},
};

using continuum::ContinuumSolver;

continuum::Material read_material(CaseNode m) {
  static constexpr std::string_view models[] = {"isotropic", "transversely_isotropic", "orthotropic"};
  const std::string model = m.choice_or("model", "isotropic", models);
  const double density = m.number("density", Range::positive(), "kg/m^3");
  continuum::Material material;
  if (model == "isotropic") {
    material = continuum::Material::isotropic(m.number("E", Range::positive(), "Pa"),
                                              m.number("nu", Range::open_between(-1.0, 0.5), "1"), density);
  } else if (model == "orthotropic") {
    const auto modulus = [&m](const char* key) { return m.number(key, Range::positive(), "Pa"); };
    const auto ratio = [&m](const char* key) { return m.number_or(key, 0.0, Range::open_between(-1.0, 1.0), "1"); };
    const std::array<double, 3> E{modulus("E_x"), modulus("E_y"), modulus("E_z")};
    const std::array<double, 3> G{modulus("G_yz"), modulus("G_xz"), modulus("G_xy")};
    const std::array<double, 3> nu{ratio("nu_xy"), ratio("nu_xz"), ratio("nu_yz")};
    try {
      material = continuum::Material::orthotropic(E, G, nu, density);
    } catch (const InputError& e) {
      m.fail("model", e.what());
    }
  } else {
    const double E_L = m.number("E_L", Range::positive(), "Pa"), E_T = m.number("E_T", Range::positive(), "Pa");
    const double nu_LT = m.number("nu_LT", Range::open_between(-1.0, 0.5), "1");
    const double nu_TT = m.number("nu_TT", Range::open_between(-1.0, 1.0), "1");
    const double G_LT = m.number("G_LT", Range::positive(), "Pa");
    const Vec3 axis = m.vec3("axis", Range::any(), "1");
    if (!(norm(axis) > 0.0)) m.fail("axis", "expected a non-zero direction");
    material = continuum::Material::transversely_isotropic(E_L, E_T, nu_LT, nu_TT, G_LT, normalized(axis), density);
  }
  material.inertia = m.vec3_or("inertia", {1.0, 1.0, 1.0}, {0.0, 1.0, true, false}, "1");
  m.finish();
  return material;
}

// What continuum: says, read before anything is built.
struct ContinuumBoundary {
  CaseNode node;  // where its errors are: its group is checked once the mesh is read
  std::string group{};
  std::string kind{};  // fixed | displacement | velocity | traction
  Vec3 value{};        // m, m/s or Pa by kind
  std::array<bool, 3> components{true, true, true};
  double rise = 0.0, duration = INFINITY;  // velocity, s
};
struct ContinuumCaseSettings {
  CaseNode mesh_node;  // where mesh errors are reported
  std::string solver_name{};
  continuum::ContinuumSettings solver{};
  bool is_static = false;
  double damping = 0.0;  // 1/s
  std::vector<ContinuumBoundary> boundaries{};
};
// What coupling: says; its overlap zone is built (and so checked) as it is read.
struct CouplingCaseSettings {
  CaseNode node;  // the section: the coupling library's errors are reported at their key
  coupling::OverlapZone zone;
  coupling::CoupledOptions options{};
  bool stop_on_damage_in_overlap = true;
  struct Tie {
    CaseNode node;
    std::string group;
    std::array<bool, 3> components;
  };
  std::vector<Tie> ties{};  // resolved to DEs when the scene is coupled
  std::optional<BandFollow> follow{};  // coupling.overlap.band.follow
};

// An error of the coupling library at its key in the case's coupling section: a SettingError
// names the key (quadrature, petsc_options, mass_floor, ...); any other is about the overlap.
[[noreturn]] void fail_at_coupling_key(const CaseNode& section, const InputError& e) {
  if (const auto* setting = dynamic_cast<const SettingError*>(&e)) section.fail(setting->key(), setting->message());
  section.fail("overlap", e.what());
}

// `components: [x, z]` of a mapping: which of x, y, z it names.
std::array<bool, 3> read_components(CaseNode node) {
  std::array<bool, 3> out{false, false, false};
  for (const std::string& c : node.strings("components")) {
    if (c != "x" && c != "y" && c != "z") node.fail("components", "expected a list of x, y, z, got '" + c + "'");
    out[static_cast<std::size_t>(c[0] - 'x')] = true;
  }
  return out;
}

ContinuumBoundary read_continuum_boundary(CaseNode bc) {
  static constexpr std::string_view kinds[] = {"fixed", "displacement", "velocity", "traction"};
  ContinuumBoundary out{bc};
  out.group = bc.string("group");
  out.kind = bc.choice("type", kinds);
  if (out.kind == "traction") {
    out.value = bc.vec3("value", Range::any(), "Pa");
    bc.finish();
    return out;
  }
  if (bc.has("components")) out.components = read_components(bc);
  if (out.kind == "displacement") {
    out.value = bc.vec3("value", Range::any(), "m");
  } else if (out.kind == "velocity") {
    out.value = bc.vec3("value", Range::any(), "m/s");
    out.rise = bc.number_or("rise", 0.0, Range::non_negative(), "s");
    out.duration = bc.number_or("duration", INFINITY, Range::positive(), "s");
    if (out.rise > out.duration) bc.fail("rise", "the rise time must not exceed the duration");
  }
  bc.finish();
  return out;
}

ContinuumCaseSettings read_continuum(CaseNode section, const std::string& extra_petsc_options) {
  std::vector<std::string_view> names;
  for (const auto& e : continuum::continuum_solvers()) names.push_back(e.name);
  std::string name = section.choice("solver", names);
  CaseNode mesh = section.child("mesh");
  ContinuumCaseSettings out{mesh, std::move(name)};
  out.solver.mesh.path = mesh.existing_file("file").string();
  out.solver.mesh.size = mesh.number_or("size", 0.0, Range::non_negative(), "m");
  out.solver.mesh.order = int(mesh.integer_or("order", 1, Range::between(1, 2)));
  if (mesh.has("join")) {
    CaseNode join_node = mesh.child("join");
    const Region join = Region::read(join_node);
    out.solver.mesh.joined = [join](const Vec3& x) { return join.contains(x); };
    out.solver.mesh.joined_name = join_node.where() + ": " + join.describe();
  }
  mesh.finish();
  out.solver.materials.push_back({"", read_material(section.child("material"))});
  static constexpr std::string_view shapes[] = {"sibson", "laplace"};
  out.solver.shape_functions = section.choice_or("shape_functions", "sibson", shapes);
  out.solver.nem_stabilization = section.number_or("stabilization", 1.0, Range::positive(), "1");
  const std::string own_options = section.string_or("petsc_options", "");
  out.solver.petsc_options = own_options + " " + extra_petsc_options;
  static constexpr std::string_view analyses[] = {"explicit", "static"};
  out.is_static = section.choice_or("analysis", "explicit", analyses) == "static";
  static constexpr std::string_view kinematics[] = {"small", "finite"};
  out.solver.kinematics = continuum::kinematics_from_name(section.choice_or("kinematics", "small", kinematics));
  if (out.is_static && out.solver.kinematics == continuum::Kinematics::finite)
    section.fail("kinematics", "finite is for analysis: explicit (the static solve is linear)");
  out.damping = section.number_or("damping", 0.0, Range::non_negative(), "1/s");
  if (out.is_static && out.damping > 0.0) section.fail("damping", "is for analysis: explicit (a static solve has no velocity)");
  // Options that nothing reads are an error, not silence: the explicit step solves nothing.
  const bool any_options = out.solver.petsc_options.find_first_not_of(' ') != std::string::npos;
  if (any_options && !out.is_static) {
    if (!own_options.empty()) section.fail("petsc_options", "is read by analysis: static only (an explicit run solves no system)");
    throw InputError("--petsc: PETSc options are read by a static continuum solve only; this case's continuum is explicit");
  }
  if (any_options) try {
      continuum::ContinuumSolver::check_static_solver_options(out.solver.petsc_options);
    } catch (const SettingError& e) {
      const bool both = extra_petsc_options.find_first_not_of(' ') != std::string::npos;
      if (!own_options.empty()) section.fail("petsc_options", both ? e.message() + " (with --petsc)" : e.message());
      throw InputError("--petsc: " + e.message());
    }
  for (CaseNode bc : section.list_or_empty("boundary")) out.boundaries.push_back(read_continuum_boundary(bc));
  section.finish();
  return out;
}

coupling::OverlapZone read_overlap(CaseNode overlap, const coupling::OverlapZone::Weighting& weighting,
                                   std::optional<BandFollow>& follow) {
  static constexpr std::string_view axes[] = {"x", "y", "z"};
  static constexpr std::string_view box_sides[] = {"lower", "upper"};
  static constexpr std::string_view cylinder_sides[] = {"base", "top"};
  const auto read_shell = [](CaseNode shell) {
    const auto inner = shell.vec3_list("inner", Range::any(), "m"), outer = shell.vec3_list("outer", Range::any(), "m");
    if (inner.size() != 2) shell.fail("inner", "expected two corners [[x0,y0,z0],[x1,y1,z1]]");
    if (outer.size() != 2) shell.fail("outer", "expected two corners [[x0,y0,z0],[x1,y1,z1]]");
    shell.finish();
    return std::make_pair(Box{inner[0], inner[1]}, Box{outer[0], outer[1]});
  };
  if (overlap.has("shell")) {
    const auto [inner, outer] = read_shell(overlap.child("shell"));
    overlap.finish();
    return coupling::OverlapZone::shell(inner, outer, weighting);
  }
  if (overlap.has("shells")) {
    std::vector<std::pair<Box, Box>> shells;
    for (CaseNode shell : overlap.list_or_empty("shells")) shells.push_back(read_shell(shell));
    if (shells.empty() || shells.size() > static_cast<std::size_t>(coupling::OverlapZone::kMaxShells))
      overlap.fail("shells", "expected 1 to " + std::to_string(coupling::OverlapZone::kMaxShells) + " shells {inner, outer}");
    overlap.finish();
    return coupling::OverlapZone::shells(shells, weighting);
  }
  if (overlap.has("band")) {
    CaseNode band = overlap.child("band");
    const int axis = band.choice("axis", axes)[0] - 'x', along = band.choice("along", axes)[0] - 'x';
    const double center = band.number("center", Range::any(), "m"), half = band.number("half_thickness", Range::positive(), "m");
    const double width = band.number("width", Range::positive(), "m");
    const double from = band.number("from", Range::any(), "m"), to = band.number("to", Range::any(), "m");
    if (band.has("follow")) {
      CaseNode f = band.child("follow");
      follow = BandFollow{f.number("margin", Range::positive(), "m"), f.number("ahead", Range::positive(), "m"),
                          f.number_or("behind", INFINITY, Range::positive(), "m"), f.number("until", Range::any(), "m"), axis, along, center, from, to,
                          width, f.number_or("settle_time", 0.0, Range::non_negative(), "s"),
                          f.number_or("settle_length", 6.0e-3, Range::positive(), "m"),
                          static_cast<int>(f.integer_or("relax_steps", 4000, Range::between(0, 1000000))), f.where()};
      if (follow->ahead <= follow->margin)
        f.fail("ahead", "expected more than margin (" + std::to_string(follow->margin) + " m): the band would move again at once");
      if (follow->until < to) f.fail("until", "expected the band's furthest end, at or beyond its to (" + std::to_string(to) + " m)");
      f.finish();
    }
    band.finish();
    overlap.finish();
    try {
      return coupling::OverlapZone::band(axis, center, half, width, along, from, to, weighting);
    } catch (const SettingError& e) {  // its checks of the values, each naming its key
      band.fail(e.key(), e.message());
    }
  }
  const Region region = Region::read(overlap);
  if (const auto* box = std::get_if<Box>(&region.shape())) {
    const int axis = overlap.choice("axis", axes)[0] - 'x';
    const bool lower = overlap.choice("dem_side", box_sides) == "lower";
    overlap.finish();
    return coupling::OverlapZone::box(*box, axis, lower, weighting);
  }
  if (const auto* cylinder = std::get_if<Cylinder>(&region.shape())) {
    if (cylinder->length < 0.0) overlap.fail("cylinder", "an overlap cylinder needs a length");
    const bool base = overlap.choice("dem_side", cylinder_sides) == "base";
    overlap.finish();
    return coupling::OverlapZone::cylinder(*cylinder, base, weighting);
  }
  overlap.fail("box", "an overlap is a box, a cylinder, a shell, shells or a band");
}


CouplingCaseSettings read_coupling(CaseNode section) {
  coupling::OverlapZone::Weighting weighting;
  static constexpr std::string_view shapes[] = {"linear", "cubic", "constant"};
  weighting.shape = coupling::weight_shape_from_name(section.choice_or("weight", "linear", shapes));
  weighting.constant_value = section.number_or("constant_value", 0.5, Range::open_between(0.0, 1.0), "1");
  weighting.mass_floor = section.number_or("mass_floor", 0.05, Range::open_between(0.0, 1.0), "1");
  CaseNode overlap = section.child("overlap");
  std::optional<coupling::OverlapZone> zone;
  std::optional<BandFollow> follow;
  try {
    zone = read_overlap(overlap, weighting, follow);
  } catch (const InputError& e) {  // the zone's own checks (extents, inner and outer boxes)
    fail_at_coupling_key(section, e);
  }
  CouplingCaseSettings out{section, *zone};
  out.follow = follow;
  static constexpr std::string_view mediators[] = {"coarse", "fine"};
  static constexpr std::string_view types[] = {"l2", "h1"};
  out.options.coupling.mediator = coupling::mediator_from_name(section.choice_or("mediator", "coarse", mediators));
  out.options.coupling.type = coupling::coupling_type_from_name(section.choice_or("type", "l2", types));
  if (out.options.coupling.type == coupling::CouplingType::h1)
    out.options.coupling.length = section.number("length", Range::positive(), "m");
  static constexpr std::string_view on_damage[] = {"stop", "warn", "hold"};
  const std::string on_damage_in_overlap = section.choice_or("on_damage_in_overlap", "stop", on_damage);
  out.stop_on_damage_in_overlap = on_damage_in_overlap == "stop";
  out.options.hold_overlap_failures = on_damage_in_overlap == "hold";
  const std::optional<long long> substeps = section.integer_or_auto("continuum_substeps", 1, Range::between(1, 1000));
  out.options.continuum_substeps = substeps ? static_cast<int>(*substeps) : 0;  // 0: auto
  for (CaseNode tie : section.list_or_empty("ties")) {
    out.ties.push_back({tie, tie.string("group"), read_components(tie)});
    tie.finish();
  }
  if (!out.ties.empty() && !out.options.coupling.fine_l2())
    section.fail("ties", "ties of some components need mediator: fine and type: l2 (a multiplier per DE)");
  static constexpr std::string_view quadratures[] = {"plain", "consistent"};
  out.options.consistent_quadrature = section.choice_or("quadrature", "plain", quadratures) == "consistent";
  static constexpr std::string_view solvers[] = {"petsc", "direct"};
  if (section.choice_or("solver", "petsc", solvers) == "petsc")
    out.options.multiplier_petsc_options = section.string_or("petsc_options", "");
  else if (section.has("petsc_options"))
    section.fail("petsc_options", "is read by coupling.solver: petsc only (the direct solver has no options)");
  else
    out.options.multiplier_petsc_options.reset();
  section.finish();
  return out;
}

// Both models advanced together by the Arlequin coupling (coupling::CoupledModel), which
// finalized the DEM; the continuum part keeps its solver, this model the coupling.
class Coupled final : public SceneModel {
 public:
  Coupled(dem::DemModel& dem, const ContinuumPart& continuum, std::unique_ptr<coupling::CoupledModel> model,
          bool stop_on_damage_in_overlap)
      : dem_(dem), continuum_(continuum), model_(std::move(model)), stop_on_damage_(stop_on_damage_in_overlap) {}
  void step(double dt) override { model_->step(dt); }
  bool accepts_set_state() const override { return model_->opens_macro_step(); }
  void resume_from_set_state() override { model_->resume_from_set_state(); }
  double displacement_residual() const override { return model_->displacement_residual(); }
  double arrest(std::span<const std::uint32_t> ids) override { return model_->arrest(ids); }
  void save_accelerations(StateArchive& archive) const override { model_->save_accelerations(archive); }
  RelaxationReport relax(double dt, int steps, const StateArchive& target) override {
    const auto r = model_->relax(dt, steps, target);
    return {r.steps, r.imbalance_before, r.imbalance_after, r.free_rigid_motions, r.fracture};
  }
  std::optional<OverlapDamageReport> damage_in_overlap() override {
    const auto damage = model_->damage_in_overlap();
    if (!damage) return std::nullopt;
    const dem::BreakEvent& e = damage->first;
    const dem::BondSet& set = *dem_.bond_sets()[e.set];
    std::ostringstream line;
    line << "damage reached the coupling overlap: bond " << e.bond << " of '" << set.name << "' (DEs " << set.first()[e.bond]
         << " and " << set.second()[e.bond] << ") " << (damage->held ? "met its failure criterion" : "broke") << " at t = " << e.time
         << " s where the DEM's weight is " << damage->weight;
    if (damage->breaks > 1) line << " (and " << damage->breaks - 1 << " more there in the step)";
    if (damage->held) line << "; held intact";
    return OverlapDamageReport{line.str(), damage->breaks, stop_on_damage_ && !damage->held, damage->held};
  }
  double critical_time_step() const override { return model_->critical_time_step(); }
  SceneEnergies energies() const override {
    return {dem_.energies(), model_->continuum_kinetic_energy(), continuum_.strain_energy(), model_->coupling_work(),
            continuum_.dissipated()};
  }
  bool coupled() const override { return true; }
  std::optional<CouplingMonitorValues> monitor() const override {
    const coupling::CouplingMonitor m = model_->monitor();
    return CouplingMonitorValues{m.constraint_residual, m.velocity_mismatch, m.max_velocity_mismatch};
  }
  void write_fields(FieldsWriter& fields, const OutputPlan& plan) const override {
    continuum_.write_fields(fields);
    write_dem_fields(dem_, fields, plan);
  }
  void save_state(StateArchive& archive) const override { model_->save_state(archive); }
  void load_state(const StateArchive& archive) override { model_->load_state(archive); }
  std::string summary() const override { return model_->summary(); }
  void describe(Json& counts) const override { counts["coupled_particles"] = model_->operators().num_particles(); }

 private:
  const dem::DemModel& dem_;
  const ContinuumPart& continuum_;
  std::unique_ptr<coupling::CoupledModel> model_;
  bool stop_on_damage_;  // coupling.on_damage_in_overlap
};

class Part final : public ContinuumPart {
 public:
  Part(ContinuumCaseSettings settings, std::optional<CouplingCaseSettings> coupling)
      : static_(settings.is_static), petsc_options_(settings.solver.petsc_options) {
    if (coupling) {
      coupling_ = std::move(coupling);
      const coupling::OverlapZone& zone = coupling_->zone;
      settings.solver.mesh.left_out = [zone](const std::array<Vec3, 4>& v) { return zone.hull_in_pure_dem_zone(v); };
      settings.solver.mesh.left_out_name =
          "the pure-DEM zone of coupling.overlap (" + coupling_->node.where("overlap") + ": " + zone.description() + ")";
    }
    try {
      solver_ = continuum::make_continuum_solver(settings.solver_name, settings.solver);
      solver_->set_damping(settings.damping);
    } catch (const InputError& e) {
      settings.mesh_node.fail("file", e.what());
    }
    for (const ContinuumBoundary& bc : settings.boundaries) apply_boundary(bc);
  }

  ContinuumSolver& solver() override { return *solver_; }
  bool is_static() const override { return static_; }
  double critical_time_step() const override { return static_ ? INFINITY : solver_->critical_time_step(); }
  void step(double dt) override { solver_->step(dt); }
  void set_affine_displacement(const std::array<Vec3, 3>& H) override {
    const auto& x = solver_->nodes();
    continuum::Field u(3 * x.size());
    for (std::size_t n = 0; n < x.size(); ++n) {
      const Vec3 hx = rows_times(H, x[n]);
      for (int c = 0; c < 3; ++c) u[3 * n + c] = hx[c];
    }
    solver_->set_initial_displacement(u);
  }

  bool in_dem_domain(const Vec3& x) const override { return !coupling_ || coupling_->zone.in_dem_domain(x); }
  const std::optional<BandFollow>& band_follow() const override {
    static const std::optional<BandFollow> none;
    return coupling_ ? coupling_->follow : none;
  }
  const std::vector<Vec3>& node_positions() const override { return solver_->nodes(); }
  double dem_weight(const Vec3& x) const override { return coupling_ ? coupling_->zone.alpha_d(x) : 0.0; }
  double vertex_plane_from(int axis, double x) const override {
    const continuum::Mesh& mesh = solver_->mesh();
    double plane = INFINITY;
    for (int e = 0; e < mesh.num_tets(); ++e)
      for (int k = 0; k < 4; ++k)
        if (const double c = mesh.nodes()[mesh.tet(e)[k]][axis]; c >= x && c < plane) plane = c;
    return plane;
  }
  std::vector<std::uint8_t> node_sides(int axis, double center) const override {
    const continuum::Mesh& mesh = solver_->mesh();
    std::vector<std::uint8_t> side(mesh.num_nodes(), 0);
    for (int e = 0; e < mesh.num_tets(); ++e) {
      const int* t = mesh.tet(e);
      double centroid = 0.0;
      for (int k = 0; k < 4; ++k) centroid += 0.25 * mesh.nodes()[t[k]][axis];
      for (int k = 0; k < mesh.nodes_per_tet(); ++k) side[t[k]] |= centroid < center ? 1 : 2;
    }
    return side;
  }
  bool prescribed(std::size_t dof) const override { return solver_->is_fixed(static_cast<int>(dof)); }
  void internal_force(const std::vector<double>& u, std::vector<double>& f) const override { solver_->internal_force(u, f); }
  std::vector<double> stiffness_diagonal() const override { return solver_->stiffness_diagonal(); }
  ShapeValues shape_values(const std::vector<Vec3>& points) const override {
    ShapeValues rows(points.size());
    const auto take = [&rows](const continuum::InterpolationOperator& N, std::size_t first) {
      for (int p = 0; p < N.outerSize(); ++p)
        for (continuum::InterpolationOperator::InnerIterator it(N, p); it; ++it)
          if (it.value() != 0.0) rows[first + p].emplace_back(static_cast<int>(it.col()), it.value());
    };
    try {
      take(solver_->interpolation(points), 0);
    } catch (const InputError&) {  // a point outside the mesh: the others one by one
      for (std::size_t p = 0; p < points.size(); ++p) try {
          take(solver_->interpolation({points[p]}), p);
        } catch (const InputError&) {
        }
    }
    return rows;
  }
  std::unique_ptr<SceneModel> couple(dem::DemModel& dem) override {
    coupling::CoupledOptions options = coupling_->options;
    options.held_continuum_dofs = held_dofs_;
    options.driven_des = dem.driven_particles();
    if (!coupling_->ties.empty()) options.tied_components.assign(dem.particles.size(), {true, true, true});
    for (const CouplingCaseSettings::Tie& tie : coupling_->ties) {
      const int group = dem.group_index(tie.group);
      if (group < 0) tie.node.fail("group", "no DE group '" + tie.group + "' (a weave has weft, stuffer and binder)");
      for (std::uint32_t i : dem.members(group)) options.tied_components[i] = tie.components;
    }
    try {
      return std::make_unique<Coupled>(dem, *this, std::make_unique<coupling::CoupledModel>(dem, *solver_, coupling_->zone, options),
                                       coupling_->stop_on_damage_in_overlap);
    } catch (const InputError& e) {  // the coupling's own checks (DEs in the overlap, masses, quadrature)
      fail_at_coupling_key(coupling_->node, e);
    }
  }
  void solve_static() override { solver_->solve_static(petsc_options_); }
  bool has_group(const std::string& name) const override { return solver_->mesh().has_group(name); }

  Vec3 mean_displacement(const std::string& group) const override { return node_mean(solver_->displacement(), group); }
  Vec3 mean_velocity(const std::string& group) const override { return node_mean(solver_->velocity(), group); }
  Vec3 reaction_on(const std::string& group) const override {
    Vec3 sum{};
    for (int n : solver_->mesh().group(group).nodes) sum -= node_vector(solver_->force(), n);
    return sum;
  }
  std::array<double, 2> affine_deviation(const std::array<Vec3, 3>& H) const override {
    std::array<double, 2> out{0.0, 0.0};
    const auto& X = solver_->nodes();
    for (std::size_t n = 0; n < X.size(); ++n) {
      const Vec3 affine = rows_times(H, X[n]);
      out[0] = std::max(out[0], norm(node_vector(solver_->displacement(), int(n)) - affine));
      out[1] = std::max(out[1], norm(affine));
    }
    return out;
  }
  double kinetic_energy() const override { return solver_->kinetic_energy(); }
  double strain_energy() const override { return solver_->strain_energy(); }
  double external_work() const override { return solver_->external_work(); }
  double verlet_correction(double dt) const override { return solver_->verlet_correction(dt); }
  double dissipated() const override { return solver_->dissipated(); }
  void save_state(StateArchive& archive) const override { solver_->save_state(archive, "continuum/"); }
  void load_state(const StateArchive& archive) override { solver_->load_state(archive, "continuum/"); }

  void write_fields(FieldsWriter& fields) const override {
    const auto& mesh = solver_->mesh();
    const int npe = mesh.nodes_per_tet();
    // VTK/XDMF quadratic tetrahedron: corners, then edges (0,1) (1,2) (0,2) (0,3) (1,3) (2,3);
    // our node 4+k sits on kTetEdges[k] = (0,1) (0,2) (0,3) (1,2) (1,3) (2,3).
    static constexpr int vtk_from_ours[10] = {0, 1, 2, 3, 4, 7, 5, 6, 8, 9};
    std::vector<std::int64_t> connectivity;
    connectivity.reserve(std::size_t(mesh.num_tets()) * npe);
    for (int e = 0; e < mesh.num_tets(); ++e)
      for (int k = 0; k < npe; ++k) connectivity.push_back(mesh.tet(e)[npe == 4 ? k : vtk_from_ours[k]]);
    fields.add_grid("continuum", mesh.nodes(),
                    npe == 4 ? FieldsWriter::CellKind::Tetrahedron : FieldsWriter::CellKind::Tetrahedron10, connectivity);
    fields.add_point_field("continuum", "displacement", as_vectors(solver_->displacement()));
    fields.add_point_field("continuum", "velocity", as_vectors(solver_->velocity()));
    // Stress lives at the method's integration points: a point cloud of its own.
    const auto stress = solver_->point_stress();
    fields.add_grid("continuum_points", solver_->point_positions(), FieldsWriter::CellKind::Vertex, {});
    static constexpr const char* names[6] = {"stress_xx", "stress_yy", "stress_zz", "stress_yz", "stress_xz", "stress_xy"};
    std::vector<double> component(stress.size()), mises(stress.size());
    for (int c = 0; c < 6; ++c) {
      for (std::size_t q = 0; q < stress.size(); ++q) component[q] = stress[q](c);
      fields.add_point_field("continuum_points", names[c], component);
    }
    for (std::size_t q = 0; q < stress.size(); ++q) {
      const auto& s = stress[q];
      mises[q] = std::sqrt(0.5 * ((s(0) - s(1)) * (s(0) - s(1)) + (s(1) - s(2)) * (s(1) - s(2)) + (s(2) - s(0)) * (s(2) - s(0))) +
                           3.0 * (s(3) * s(3) + s(4) * s(4) + s(5) * s(5)));
    }
    fields.add_point_field("continuum_points", "von_mises", mises);
  }

  void describe(Json& counts) const override {
    counts["continuum_nodes"] = solver_->num_nodes();
    counts["continuum_tetrahedra"] = solver_->mesh().num_tets();
    counts["continuum_order"] = solver_->mesh().order();
    if (solver_->mesh().tets_left_out() > 0) counts["continuum_tetrahedra_left_out"] = solver_->mesh().tets_left_out();
    if (solver_->mesh().nodes_joined() > 0) counts["continuum_nodes_joined"] = solver_->mesh().nodes_joined();
  }

 private:
  static Vec3 node_vector(const continuum::Field& f, int n) { return {f[3 * n], f[3 * n + 1], f[3 * n + 2]}; }
  Vec3 node_mean(const continuum::Field& f, const std::string& group) const {
    const auto& nodes = solver_->mesh().group(group).nodes;
    Vec3 sum{};
    for (int n : nodes) sum += node_vector(f, n);
    return sum / double(nodes.size());
  }
  static std::vector<Vec3> as_vectors(const continuum::Field& f) {
    std::vector<Vec3> out(f.size() / 3);
    for (std::size_t n = 0; n < out.size(); ++n) out[n] = node_vector(f, int(n));
    return out;
  }

  // Checks the boundary's group against the mesh and imposes it.
  void apply_boundary(const ContinuumBoundary& bc) {
    const std::string& group = bc.group;
    if (!solver_->mesh().has_group(group)) {
      std::string known;
      for (const auto& g : solver_->mesh().groups()) known += (known.empty() ? "" : ", ") + g.name;
      bc.node.fail("group", "the mesh has no physical group '" + group + "' (it has: " + known + ")");
    }
    if (bc.kind == "traction") {
      if (solver_->mesh().group(group).dim != 2) bc.node.fail("group", "a traction needs a surface group");
      solver_->add_traction(group, [t = bc.value](const Vec3&, double) { return t; });
      return;
    }
    continuum::VectorFunction g;  // none for fixed or a zero motion: a still support (ContinuumSolver::fix)
    if (bc.kind == "displacement" && bc.value != Vec3{}) {
      g = [u = bc.value](const Vec3&, double) { return u; };
    } else if (bc.kind == "velocity" && bc.value != Vec3{}) {
      // Velocity v with the DEM's rise (common/rise.hpp) until `duration`, then held: g(t) is its
      // integral. One rise for both: a coupled run's load strips then move as the pure DEM's load
      // DEs do.
      g = [v = bc.value, duration = bc.duration, rise = bc.rise](const Vec3&, double t) {
        return v * rise_travel(std::min(t, duration), rise);
      };
    }
    solver_->fix(group, bc.components, g);
    const auto dofs = coupling::group_dofs(*solver_, group, bc.components);
    held_dofs_.insert(held_dofs_.end(), dofs.begin(), dofs.end());
  }

  bool static_;
  std::string petsc_options_;
  std::unique_ptr<ContinuumSolver> solver_;
  std::optional<CouplingCaseSettings> coupling_;  // with a coupling section
  std::vector<int> held_dofs_;  // dofs with essential conditions (no coupling correction)
};

}  // namespace

std::span<const SchemaSection> ContinuumPart::schema() { return continuum_sections; }

std::unique_ptr<ContinuumPart> ContinuumPart::read(CaseNode section, std::optional<CaseNode> coupling,
                                                   const std::string& extra_petsc_options) {
  ContinuumCaseSettings settings = read_continuum(section, extra_petsc_options);
  std::optional<CouplingCaseSettings> coupled;
  if (coupling) {
    if (settings.is_static) coupling->fail("overlap", "a coupled continuum needs continuum.analysis: explicit");
    coupled = read_coupling(*coupling);
  }
  return std::make_unique<Part>(std::move(settings), std::move(coupled));
}

}  // namespace arlequin::app
