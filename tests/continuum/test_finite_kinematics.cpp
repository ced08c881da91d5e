// SPDX-License-Identifier: GPL-3.0-or-later
// Finite kinematics (ContinuumSolver contract; docs/theory.md#finite-kinematics): total Lagrangian
// St Venant-Kirchhoff on the points of every method. Closed forms on the unit cube: a rigid
// rotation strains nothing, a uniaxial stretch has E_xx = (lambda^2 - 1) / 2 and the face force
// lambda S_xx; the force is the exact gradient of the energy.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/error.hpp"
#include "continuum_test_util.hpp"

using namespace arlequin;
using namespace arlequin::continuum;
using namespace arlequin::continuum::testing;

namespace {

const Material material = Material::isotropic(1e3, 0.3, 1.0);

struct Method {
  const char* solver;
  int order;
};
const Method methods[] = {{"fe", 1}, {"fe", 2}, {"nem", 1}};

std::unique_ptr<ContinuumSolver> make(const Method& m, Kinematics k) {
  ContinuumSettings s = settings("unit_cube.geo", 0.34, m.order, material);
  s.kinematics = k;
  return make_continuum_solver(m.solver, s);
}

void set_displacement(ContinuumSolver& s, const std::function<Vec3(const Vec3&)>& u) {
  for (int n = 0; n < s.num_nodes(); ++n) {
    const Vec3 v = u(s.nodes()[n]);
    for (int c = 0; c < 3; ++c) s.displacement()[3 * n + c] = v[c];
  }
}

double norm_of(const Field& f) {
  double sum = 0.0;
  for (double x : f) sum += x * x;
  return std::sqrt(sum);
}

// u = (R - I)(x - c), R a rotation by 60 degrees about a skew axis through c.
Vec3 rotated(const Vec3& x) {
  const Vec3 c{0.5, 0.5, 0.5}, k = normalized(Vec3{1.0, 2.0, 3.0}), r = x - c;
  const double t = M_PI / 3.0;
  return r * std::cos(t) + cross(k, r) * std::sin(t) + k * (dot(k, r) * (1.0 - std::cos(t))) - r;
}

// The strain energy summed point by point from the points' strains and stresses (Eigen, the
// points' own gradients): independent of FiniteStrainForce's tiles, batches and factored
// gradients, which strain_energy() goes through.
double point_sum_energy(const ContinuumSolver& s) {
  const auto strain = s.point_strain(), stress = s.point_stress();
  double e = 0.0;
  for (size_t q = 0; q < strain.size(); ++q) e += 0.5 * s.point_weights()[q] * strain[q].dot(stress[q]);
  return e;
}

}  // namespace

// Finite kinematics see no strain in a rigid rotation; small ones see a strain (cos t - 1) and
// the forces it makes, so this test fails for a solver that stayed linear.
TEST(FiniteKinematics, RigidRotationOfSixtyDegreesStrainsNothing) {
  for (const Method& m : methods) {
    auto finite = make(m, Kinematics::finite), small = make(m, Kinematics::small);
    set_displacement(*finite, rotated);
    set_displacement(*small, rotated);
    Field f_finite, f_small;
    finite->internal_force(finite->displacement(), f_finite);
    small->internal_force(small->displacement(), f_small);
    ASSERT_GT(norm_of(f_small), 1.0) << m.solver << m.order;  // E |cos t - 1| times the faces' areas
    EXPECT_LT(norm_of(f_finite), 1e-12 * norm_of(f_small)) << m.solver << m.order;
    EXPECT_GT(small->strain_energy(), 10.0) << m.solver << m.order;
    EXPECT_LT(finite->strain_energy(), 1e-24 * small->strain_energy()) << m.solver << m.order;
  }
}

// u = (stretch - 1) x e_x: F = diag(stretch, 1, 1), E_xx = (stretch^2 - 1) / 2, S = C E, energy
// S_xx E_xx / 2 per unit volume, and the nodes of the face x = 1 carry P_xx = stretch S_xx per
// unit area (the reaction a support would take), those of x = 0 its opposite.
TEST(FiniteKinematics, UniaxialStretchMatchesTheClosedForm) {
  const double stretch = 1.2, Exx = 0.5 * (stretch * stretch - 1.0), Sxx = material.C(0, 0) * Exx;
  for (const Method& m : methods) {
    auto s = make(m, Kinematics::finite);
    set_displacement(*s, [&](const Vec3& x) { return Vec3{(stretch - 1.0) * x.x, 0.0, 0.0}; });
    EXPECT_NEAR(s->strain_energy() / (0.5 * Sxx * Exx), 1.0, 1e-12) << m.solver << m.order;
    Field f;
    s->internal_force(s->displacement(), f);
    double face = 0.0, opposite = 0.0;
    for (int n = 0; n < s->num_nodes(); ++n) {
      if (std::abs(s->nodes()[n].x - 1.0) < 1e-9) face += f[3 * n];
      if (std::abs(s->nodes()[n].x) < 1e-9) opposite += f[3 * n];
    }
    EXPECT_NEAR(face / (stretch * Sxx), 1.0, 1e-10) << m.solver << m.order;
    EXPECT_NEAR(opposite / (stretch * Sxx), -1.0, 1e-10) << m.solver << m.order;
  }
}

// f_int(u).v = dE(u + t v)/dt at t = 0. E is a quartic in t, so the central difference
// D(h) = (E(h) - E(-h)) / (2 h) = f.v + a3 h^2 exactly and (4 D(h/2) - D(h)) / 3 = f.v: an
// independent check of the force to round-off, at gradients of order 0.3 (finite rotations and
// strains).
TEST(FiniteKinematics, InternalForceIsTheEnergysGradient) {
  for (const Method& m : methods) {
    auto s = make(m, Kinematics::finite);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> uni(-0.1, 0.1);
    Field u(s->displacement().size()), v(u.size());
    for (double& x : u) x = uni(rng);
    for (double& x : v) x = uni(rng);
    const auto energy_at = [&](double t) {
      for (size_t d = 0; d < u.size(); ++d) s->displacement()[d] = u[d] + t * v[d];
      return point_sum_energy(*s);
    };
    const auto central = [&](double h) { return (energy_at(h) - energy_at(-h)) / (2.0 * h); };
    const double h = 0.5, derivative = (4.0 * central(h / 2) - central(h)) / 3.0;
    Field f;
    s->internal_force(u, f);
    double fv = 0.0;
    for (size_t d = 0; d < u.size(); ++d) fv += f[d] * v[d];
    EXPECT_NEAR(fv / derivative, 1.0, 1e-9) << m.solver << m.order;
  }
}

// strain_energy() (the force's tiles, fe's factored gradients) is the point sum to round-off.
TEST(FiniteKinematics, StrainEnergyIsThePointSum) {
  for (const Method& m : methods) {
    auto s = make(m, Kinematics::finite);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> uni(-0.1, 0.1);
    for (double& x : s->displacement()) x = uni(rng);
    const double reference = point_sum_energy(*s);
    EXPECT_GT(reference, 0.0);
    EXPECT_NEAR(s->strain_energy() / reference, 1.0, 1e-12) << m.solver << m.order;
  }
}

// The static solve is linear: asking it of a finite-kinematics solver is an error, not a
// silently linear answer.
TEST(FiniteKinematics, StaticSolveIsRefused) {
  auto s = make(methods[0], Kinematics::finite);
  EXPECT_THROW(s->solve_static(), InputError);
}

// stiffness_diagonal() is K's diagonal as weighted, the tangent at the undeformed state of both
// kinematics: K_ii = d f_int,i / d u_i at u = 0, taken here from the internal force itself (central
// differences over h = 1e-6 of the cube, second order: the finite force's K_ii to ~1e-12).
TEST(FiniteKinematics, StiffnessDiagonalIsTheTangentsAtRest) {
  for (const Method& m : methods)
    for (const Kinematics k : {Kinematics::small, Kinematics::finite}) {
      auto s = make(m, k);
      s->set_weight([](const Vec3& x) { return 0.2 + 0.8 * x.x; });  // weighted as an overlap is
      const std::vector<double> diagonal = s->stiffness_diagonal();
      ASSERT_EQ(diagonal.size(), 3u * s->num_nodes());
      constexpr double h = 1e-6;
      Field u(diagonal.size(), 0.0), plus, minus;
      double worst = 0.0;
      for (size_t i = 0; i < diagonal.size(); i += 7) {
        u[i] = h;
        s->internal_force(u, plus);
        u[i] = -h;
        s->internal_force(u, minus);
        u[i] = 0.0;
        worst = std::max(worst, std::abs((plus[i] - minus[i]) / (2.0 * h) - diagonal[i]) / diagonal[i]);
      }
      // Measured: small 1.2e-16 at most (round-off; fe P1 0), finite 3.5e-11 (fe P1) to 2.9e-10 (fe
      // P2), the differences' round-off over h.
      EXPECT_LT(worst, k == Kinematics::small ? 1e-13 : 1e-9) << m.solver << " P" << m.order << (k == Kinematics::finite ? " finite" : " small");
    }
}
