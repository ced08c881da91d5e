// Shared set-up for the continuum tests: mesh paths, settings, affine fields.
#pragma once
#include <string>

#include "continuum/registry.hpp"

namespace arlequin::continuum::testing {

inline std::string mesh_path(const std::string& name) { return std::string(ARLEQUIN_SOURCE_DIR) + "/meshes/" + name; }

inline ContinuumSettings settings(const std::string& mesh, double size, int order, const Material& m) {
  ContinuumSettings s;
  s.mesh = {mesh_path(mesh), size, order};
  s.materials = {{"", m}};
  return s;
}

// A generic affine displacement field u = A x + c.
inline Vec3 affine(const Vec3& x) {
  return {1e-3 + 2e-3 * x.x - 1e-3 * x.y + 0.5e-3 * x.z, -2e-3 + 0.7e-3 * x.x + 1.5e-3 * x.y - 0.4e-3 * x.z,
          0.5e-3 - 0.3e-3 * x.x + 0.9e-3 * x.y + 1.1e-3 * x.z};
}
inline Voigt affine_strain() {
  Voigt e;
  e << 2e-3, 1.5e-3, 1.1e-3, 0.9e-3 - 0.4e-3, 0.5e-3 - 0.3e-3, -1e-3 + 0.7e-3;
  return e;
}

}  // namespace arlequin::continuum::testing
