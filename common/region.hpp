// SPDX-License-Identifier: GPL-3.0-or-later
// Regions of space used to name groups of DEs, material zones and overlap zones.
//
// A region mapping has one key naming its shape (box, cylinder, sphere, half_space: the schema
// section "region", `arlequin schema region`).
// A small relative tolerance (1e-9 of the region's size) makes boundaries inclusive despite
// round-off, so a lattice layer lying exactly on a face is inside.
#pragma once
#include <span>
#include <string>
#include <variant>

#include "common/schema.hpp"
#include "common/vec3.hpp"

namespace arlequin {

class CaseNode;

struct Box {
  Vec3 lower, upper;
  bool operator==(const Box&) const = default;
};
struct Cylinder {
  Vec3 base, axis;  // axis is unit
  double radius = 0.0;
  double length = -1.0;  // < 0: infinite
  bool operator==(const Cylinder&) const = default;
};
struct Sphere {
  Vec3 center;
  double radius = 0.0;
  bool operator==(const Sphere&) const = default;
};
struct HalfSpace {
  Vec3 point, normal;  // normal is unit
  bool operator==(const HalfSpace&) const = default;
};

class Region {
 public:
  using Shape = std::variant<Box, Cylinder, Sphere, HalfSpace>;
  explicit Region(Shape shape) : shape_(shape) {}
  // Reads one region mapping; errors name the key and what was expected. Its keys are those
  // of the schema section "region" (schema()), wherever the mapping sits.
  static Region read(CaseNode& node);
  static std::span<const SchemaSection> schema();

  bool contains(const Vec3& x) const;
  const Shape& shape() const { return shape_; }
  std::string describe() const;
  bool operator==(const Region&) const = default;

 private:
  Shape shape_;
};

}  // namespace arlequin
