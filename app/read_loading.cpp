// SPDX-License-Identifier: GPL-3.0-or-later
// The loading of a case: groups, boundary conditions, initial velocities, pulse, initial strain (and their keys).
#include "app/scene_readers.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "common/case_file.hpp"
#include "common/error.hpp"
#include "common/region.hpp"
#include "common/schema.hpp"

namespace arlequin::app {
namespace {

using dem::BoundaryCondition;
using dem::BoundaryKind;

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
    {"rise", KeyType::number, "s", Range::non_negative(), "0", "velocity: time over which it rises from 0, as (1 - cos(pi t / rise)) / 2"},
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
constexpr SchemaSection loading_sections[] = {
    {"groups[]", "a named group of DEs (a region or ids)", group_keys},
    {"boundary[]", "a DEM boundary condition", boundary_keys},
    {"initial[]", "an initial velocity", initial_keys},
    {"initial_strain", "a uniform initial strain", initial_strain_keys},
    {"pulse", "an initial velocity pulse", pulse_keys},
};

}  // namespace

std::span<const SchemaSection> loading_schema() { return loading_sections; }

void read_groups(CaseNode root, dem::DemModel& model) {
  for (CaseNode g : root.list_or_empty("groups")) {
    const std::string name = g.string("name");
    if (model.group_index(name) >= 0) g.fail("name", "group '" + name + "' is defined twice");
    const dem::ParticleSet& p = model.particles;
    std::vector<std::uint32_t> ids;
    if (g.has("ids")) {
      for (double id : g.numbers("ids", Range::between(0, double(p.size()) - 1), "1")) {
        if (id != std::floor(id)) g.fail("ids", "expected whole DE indices");
        ids.push_back(static_cast<std::uint32_t>(id));
      }
    } else {
      CaseNode region_node = g.child("region");
      const Region region = Region::read(region_node);
      region_node.finish();
      for (std::size_t i = 0; i < p.size(); ++i)
        if (region.contains(p.position[i])) ids.push_back(static_cast<std::uint32_t>(i));
    }
    if (ids.empty()) g.fail(g.has("ids") ? "ids" : "region", "group '" + name + "' contains no DE");
    model.add_group(name, std::move(ids));
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


}  // namespace arlequin::app
