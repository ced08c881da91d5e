// SPDX-License-Identifier: GPL-3.0-or-later
// Shared set-ups for the coupling tests: structured box meshes written as gmsh files, and
// DEM bars that match them (same stiffness per unit length and mass per node).
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>  // getpid

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "continuum/registry.hpp"
#include "coupling/coupled_model.hpp"
#include "dem/dem_model.hpp"
#include "dem/bonds/spring_bond.hpp"

namespace arlequin::coupling::testing {

// Box [x0, x0 + nx hx] x [0, ny hy] x [0, nz hz]; every cell is split into the six Kuhn
// tetrahedra (paths 000 -> 111, the same in every cell, so the mesh is conforming and each
// x-face is cut by its (y, z) = (0,0)-(1,1) diagonal). Written as gmsh 2.2 ASCII with the groups
// xmin, xmax (surfaces) and bar (volume); returns the path.
inline std::string write_box_mesh(const std::string& name, double x0, int nx, double hx, int ny, double hy, int nz,
                                  double hz) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "arlequin_coupling_tests";
  fs::create_directories(dir);
  const fs::path path = dir / (name + ".msh");
  auto id = [&](int i, int j, int k) { return 1 + i + (nx + 1) * (j + (ny + 1) * k); };
  auto pos = [&](int n) {
    const int i = (n - 1) % (nx + 1), j = ((n - 1) / (nx + 1)) % (ny + 1), k = (n - 1) / ((nx + 1) * (ny + 1));
    return Vec3{x0 + i * hx, j * hy, k * hz};
  };
  std::vector<std::array<int, 4>> tets;
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& p : perms) {
          std::array<int, 3> c{i, j, k};
          std::array<int, 4> t;
          t[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[p[s]];
            t[s + 1] = id(c[0], c[1], c[2]);
          }
          const Vec3 a = pos(t[0]), b = pos(t[1]), cc = pos(t[2]), d = pos(t[3]);
          if (dot(cross(b - a, cc - a), d - a) < 0) std::swap(t[2], t[3]);
          tets.push_back(t);
        }
  std::vector<std::array<int, 4>> tris;  // {group, n0, n1, n2}
  for (const auto& t : tets)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f;
      int m = 0;
      for (int v = 0; v < 4; ++v)
        if (v != skip) f[m++] = t[v];
      for (int side = 0; side < 2; ++side) {
        const double xs = side == 0 ? x0 : x0 + nx * hx;
        bool on = true;
        for (int v : f) on = on && std::abs(pos(v).x - xs) < 1e-12 * (1.0 + std::abs(xs));
        if (on) tris.push_back({side + 1, f[0], f[1], f[2]});
      }
    }
  // Our own temporary file: tests running side by side (ctest -j, or two checkouts) may write
  // the same mesh; sharing one temporary let one truncate the file another was writing.
  const fs::path tmp = dir / (name + ".msh.tmp." + std::to_string(::getpid()));
  {
    std::ofstream out(tmp);
    out.precision(17);
    out << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n3\n2 1 \"xmin\"\n2 2 \"xmax\"\n3 3 \"bar\"\n"
        << "$EndPhysicalNames\n$Nodes\n";
    const int nn = (nx + 1) * (ny + 1) * (nz + 1);
    out << nn << "\n";
    for (int n = 1; n <= nn; ++n) {
      const Vec3 x = pos(n);
      out << n << " " << x.x << " " << x.y << " " << x.z << "\n";
    }
    out << "$EndNodes\n$Elements\n" << tris.size() + tets.size() << "\n";
    int e = 1;
    for (const auto& t : tris) out << e++ << " 2 2 " << t[0] << " " << t[0] << " " << t[1] << " " << t[2] << " " << t[3] << "\n";
    for (const auto& t : tets) out << e++ << " 4 2 3 3 " << t[0] << " " << t[1] << " " << t[2] << " " << t[3] << "\n";
    out << "$EndElements\n";
  }
  fs::rename(tmp, path);
  return path.string();
}

inline std::unique_ptr<continuum::ContinuumSolver> make_continuum(const std::string& method, const std::string& mesh,
                                                                  double E, double nu, double rho,
                                                                  double nem_stabilization = 1.0) {
  continuum::ContinuumSettings s;
  s.mesh = {mesh, 0.0, 1, {}};
  s.materials = {{"", continuum::Material::isotropic(E, nu, rho)}};
  s.nem_stabilization = nem_stabilization;
  return continuum::make_continuum_solver(method, s);
}

// "1D" bar of four DE lines along x at the corners (y, z) in {0, b}^2 of a b x b cross-section,
// n DEs per line at x = k a, joined along each line by springs. The lines carry the shares of the
// cross-section that a one-cell-thick Kuhn mesh gives its corner nodes (b^2/3 on the (0,0) and
// (b,b) lines, b^2/6 on the others): spring k_l = E A_l / a, DE mass rho A_l a. With nu = 0 the
// mesh's plane axial waves are then exactly four mass-spring chains, the same as these lines when
// h = a. Group "left": the DEs at x = 0.
inline void build_four_lines(dem::DemModel& model, int n, double a, double b, double E, double rho) {
  const int left = model.add_group("left");
  const double areas[4] = {b * b / 3.0, b * b / 6.0, b * b / 6.0, b * b / 3.0};
  const Vec3 corners[4] = {{0, 0, 0}, {0, b, 0}, {0, 0, b}, {0, b, b}};
  auto stiff = std::make_unique<dem::SpringBondSet>(E * areas[0] / a);
  auto soft = std::make_unique<dem::SpringBondSet>(E * areas[1] / a);
  dem::ParticleSet& p = model.particles;
  for (int l = 0; l < 4; ++l) {
    const std::size_t first = p.size();
    for (int k = 0; k < n; ++k) {
      const std::size_t i = p.add(corners[l] + Vec3{k * a, 0, 0}, 0.5 * a, rho);
      p.inv_mass[i] = 1.0 / (rho * areas[l] * a);
      if (k == 0) model.add_members(left, std::array{static_cast<std::uint32_t>(i)});
    }
    auto& set = (l == 0 || l == 3) ? *stiff : *soft;
    for (int k = 0; k + 1 < n; ++k)
      set.add(static_cast<std::uint32_t>(first + k), static_cast<std::uint32_t>(first + k + 1), p);
  }
  model.add_bond_set(std::move(stiff));
  model.add_bond_set(std::move(soft));
}

// Simple-cubic block nx x ny x nz at spacing a from the origin, nearest (k) and face-diagonal (k)
// springs, with the shares of a cell-by-cell assembly: a bond on the surface gets the fraction of
// the cells around it that exist (edge bonds 1/4 or 1/2, face-diagonal bonds on a face 1/2), a DE
// the fraction of its 8 cells (mass rho a^3 x share). That is the lattice counterpart of a
// continuum box of the same outer size, with C11 = 3k/a, C12 = C44 = k/a: isotropic,
// E = 2.5 k/a, nu = 0.25. Group "left": the DEs at x = 0.
inline void build_block(dem::DemModel& model, std::array<int, 3> n, double a, double E, double rho) {
  const int left = model.add_group("left");
  const double k = E * a / 2.5;
  dem::ParticleSet& p = model.particles;
  auto index = [&](int i, int j, int l) { return static_cast<std::uint32_t>(i + n[0] * (j + n[1] * l)); };
  auto cells_share = [&](const std::array<int, 3>& lo, const std::array<int, 3>& span) {
    // fraction of the cells containing the segment/point [lo, lo+span] that lie in the block
    double share = 1.0;
    for (int d = 0; d < 3; ++d) {
      if (span[d] != 0) continue;
      int inside = 0;
      if (lo[d] - 1 >= 0) ++inside;
      if (lo[d] + 1 <= n[d] - 1) ++inside;
      share *= inside / 2.0;
    }
    return share;
  };
  for (int l = 0; l < n[2]; ++l)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const std::size_t id = p.add({i * a, j * a, l * a}, 0.5 * a, rho);
        p.inv_mass[id] = 1.0 / (rho * a * a * a * cells_share({i, j, l}, {0, 0, 0}));
        if (i == 0) model.add_members(left, std::array{static_cast<std::uint32_t>(id)});
      }
  auto springs = std::make_unique<dem::SpringBondSet>(k);
  std::vector<double> factor;
  const std::array<std::array<int, 3>, 9> dirs{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {1, -1, 0}, {1, 0, 1}, {1, 0, -1}, {0, 1, 1}, {0, 1, -1}}};
  for (int l = 0; l < n[2]; ++l)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
        for (const auto& d : dirs) {
          const int i2 = i + d[0], j2 = j + d[1], l2 = l + d[2];
          if (i2 < 0 || j2 < 0 || l2 < 0 || i2 >= n[0] || j2 >= n[1] || l2 >= n[2]) continue;
          std::array<int, 3> lo{std::min(i, i2), std::min(j, j2), std::min(l, l2)};
          const std::array<int, 3> span{std::abs(d[0]), std::abs(d[1]), std::abs(d[2])};
          springs->add(index(i, j, l), index(i2, j2, l2), p);
          // a nearest bond lies in 4 cells, a face diagonal in 2 (the dims it does not span)
          factor.push_back(cells_share(lo, span));
        }
  springs->scale_stiffness(factor);
  model.add_bond_set(std::move(springs));
}

// Right-moving tone burst on a lattice of spacing a and wave speed c: carrier wavelength lambda,
// Gaussian envelope of width sigma centred at x0. Returns (u, v) at x with the chain dispersion
// omega = 2c/a sin(ka/2) and group velocity c cos(ka/2).
struct ToneBurst {
  double amplitude, lambda, sigma, x0, a, c;
  double k() const { return 2.0 * std::numbers::pi / lambda; }
  double omega() const { return 2.0 * c / a * std::sin(0.5 * k() * a); }
  double group_velocity() const { return c * std::cos(0.5 * k() * a); }
  std::pair<double, double> at(double x) const {
    const double s = x - x0, env = std::exp(-0.5 * s * s / (sigma * sigma)), denv = -s / (sigma * sigma) * env;
    const double u = amplitude * env * std::sin(k() * s);
    const double v = -group_velocity() * amplitude * denv * std::sin(k() * s) - omega() * amplitude * env * std::cos(k() * s);
    return {u, v};
  }
};

}  // namespace arlequin::coupling::testing
