// Regions of space used to name groups of DEs, material zones and overlap zones.
//
// Case-file forms (one key per region):
//   {box: [[x0,y0,z0],[x1,y1,z1]]}                      axis-aligned, bounds inclusive
//   {cylinder: {base: [..], axis: [..], radius: r}}      infinite if no length, else base..base+length*axis
//   {cylinder: {base: [..], axis: [..], radius: r, length: h}}
//   {sphere: {center: [..], radius: r}}
//   {half_space: {point: [..], normal: [..]}}            points with (x - point).normal >= 0
// A small relative tolerance (1e-9 of the region's size) makes boundaries inclusive despite
// round-off, so a lattice layer lying exactly on a face is inside.
#pragma once
#include <string>
#include <variant>

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
  // Reads one region mapping; errors name the key and what was expected.
  static Region read(CaseNode& node);

  bool contains(const Vec3& x) const;
  const Shape& shape() const { return shape_; }
  std::string describe() const;
  bool operator==(const Region&) const = default;

 private:
  Shape shape_;
};

}  // namespace arlequin
