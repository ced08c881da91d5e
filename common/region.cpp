// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/region.hpp"

#include <cmath>
#include <cstdio>
#include <string_view>

#include "common/case_file.hpp"
#include "common/schema.hpp"

namespace arlequin {
namespace {

constexpr double tolerance = 1e-9;

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

Vec3 unit_vector(CaseNode& node, std::string_view key) {
  const Vec3 v = node.vec3(key, Range::any(), "1");
  const double n = norm(v);
  if (!(n > 0.0)) node.fail(key, "expected a non-zero direction vector");
  return v / n;
}

}  // namespace

constexpr KeyDoc region_keys[] = {
    {"box", KeyType::vec3_list, "m", {}, "(one shape)", "two opposite corners [[x0, y0, z0], [x1, y1, z1]]"},
    {"cylinder", KeyType::section, "", {}, "(one shape)", "a cylinder (base, axis, radius, length)"},
    {"sphere", KeyType::section, "", {}, "(one shape)", "a sphere (center, radius)"},
    {"half_space", KeyType::section, "", {}, "(one shape)", "the points on the side of a plane its normal points to (point, normal)"},
};
constexpr KeyDoc cylinder_keys[] = {
    {"base", KeyType::vec3, "m", {}, "", "centre of the base disc"},
    {"axis", KeyType::vec3, "1", {}, "", "direction from the base (normalised)"},
    {"radius", KeyType::number, "m", Range::positive(), "", "radius"},
    {"length", KeyType::number, "m", {}, "-1", "length along the axis; negative: unbounded"},
};
constexpr KeyDoc sphere_keys[] = {
    {"center", KeyType::vec3, "m", {}, "", "centre"},
    {"radius", KeyType::number, "m", Range::positive(), "", "radius"},
};
constexpr KeyDoc half_space_keys[] = {
    {"point", KeyType::vec3, "m", {}, "", "a point of the plane"},
    {"normal", KeyType::vec3, "1", {}, "", "the plane's normal, pointing into the region (normalised)"},
};
constexpr SchemaSection region_sections[] = {
    {"region", "a region: exactly one of its shapes", region_keys},
    {"region.cylinder", "a cylinder", cylinder_keys},
    {"region.sphere", "a sphere", sphere_keys},
    {"region.half_space", "a half space", half_space_keys},
};

std::span<const SchemaSection> Region::schema() { return region_sections; }

Region Region::read(CaseNode& node) {
  node.add_schema_section("region");  // the shapes' keys, wherever a region is read
  static constexpr std::string_view shapes[] = {"box", "cylinder", "sphere", "half_space"};
  int found = 0;
  for (auto s : shapes) found += node.has(s) ? 1 : 0;
  if (found != 1)
    node.fail("box", "a region needs exactly one of: box, cylinder, sphere, half_space");
  std::optional<Region> region;
  if (node.has("box")) {
    const auto corners = node.vec3_list("box", Range::any(), "m");
    if (corners.size() != 2) node.fail("box", "expected two corners [[x0,y0,z0],[x1,y1,z1]]");
    Box b{corners[0], corners[1]};
    for (int k = 0; k < 3; ++k)
      if (!(b.lower[k] <= b.upper[k])) node.fail("box", "lower corner must not exceed upper corner");
    region.emplace(b);
  } else if (node.has("cylinder")) {
    CaseNode c = node.child("cylinder");
    Cylinder cyl{c.vec3("base", Range::any(), "m"), unit_vector(c, "axis"),
                 c.number("radius", Range::positive(), "m"),
                 c.number_or("length", -1.0, Range::any(), "m")};
    c.finish();
    region.emplace(cyl);
  } else if (node.has("sphere")) {
    CaseNode s = node.child("sphere");
    Sphere sph{s.vec3("center", Range::any(), "m"), s.number("radius", Range::positive(), "m")};
    s.finish();
    region.emplace(sph);
  } else {
    CaseNode h = node.child("half_space");
    HalfSpace hs{h.vec3("point", Range::any(), "m"), unit_vector(h, "normal")};
    h.finish();
    region.emplace(hs);
  }
  return *region;
}

bool Region::contains(const Vec3& x) const {
  return std::visit(
      Overloaded{
          [&](const Box& b) {
            for (int k = 0; k < 3; ++k) {
              const double slack = tolerance * std::max(1.0, std::abs(b.upper[k] - b.lower[k]));
              if (x[k] < b.lower[k] - slack || x[k] > b.upper[k] + slack) return false;
            }
            return true;
          },
          [&](const Cylinder& c) {
            const Vec3 d = x - c.base;
            const double s = dot(d, c.axis);
            const double slack = tolerance * c.radius;
            if (c.length >= 0.0 && (s < -slack || s > c.length + slack)) return false;
            return norm2(d - s * c.axis) <= (c.radius + slack) * (c.radius + slack);
          },
          [&](const Sphere& s) {
            const double r = s.radius * (1.0 + tolerance);
            return norm2(x - s.center) <= r * r;
          },
          [&](const HalfSpace& h) { return dot(x - h.point, h.normal) >= -tolerance * std::max(1.0, norm(h.point)); },
      },
      shape_);
}

std::string Region::describe() const {
  return std::visit(Overloaded{[](const Box&) { return std::string("box"); },
                               [](const Cylinder&) { return std::string("cylinder"); },
                               [](const Sphere&) { return std::string("sphere"); },
                               [](const HalfSpace&) { return std::string("half_space"); }},
                    shape_);
}

}  // namespace arlequin
