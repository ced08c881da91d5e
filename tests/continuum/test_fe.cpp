// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <random>
#include <tuple>

#include "common/error.hpp"
#include "continuum_test_util.hpp"

using namespace arlequin;
using namespace arlequin::continuum;
using namespace arlequin::continuum::testing;

namespace {

// Affine displacement on the whole boundary, or on one face with tractions on the others:
// interior nodes and stresses must be exact.
void fe_patch_test(int order) {
  const Material mat = Material::isotropic(1e3, 0.3, 1.0);
  for (bool traction : {false, true}) {
    auto s = make_continuum_solver("fe", settings("unit_cube.geo", 0.34, order, mat));
    const PatchErrors e = patch_test(*s, mat, traction);
    EXPECT_LT(e.displacement, 1e-10) << "P" << order << (traction ? " traction" : "");
    EXPECT_LT(e.stress, 1e-10) << "P" << order << (traction ? " traction" : "");
  }
}

// Runs `steps` central-difference steps from random velocities at factor * dt_c, returns the
// largest total energy seen divided by the initial one.
double energy_growth(const std::string& method, int order, double factor, int steps) {
  auto s = make_continuum_solver(method, settings("unit_cube.geo", 0.3, order, Material::isotropic(1.0, 0.3, 1.0)));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(-1, 1);
  for (double& v : s->velocity()) v = uni(rng);
  s->compute_forces();
  const double dt = factor * s->critical_time_step();
  const double e0 = s->kinetic_energy() + s->strain_energy();
  double emax = e0;
  try {
    for (int i = 0; i < steps; ++i) {
      s->step(dt);
      emax = std::max(emax, s->kinetic_energy() + s->strain_energy());
      if (emax > 1e12 * e0) break;
    }
  } catch (const RunError&) {
    return 1e300;
  }
  return emax / e0;
}

}  // namespace

TEST(ContinuumFe, PatchTestP1) { fe_patch_test(1); }
TEST(ContinuumFe, PatchTestP2) { fe_patch_test(2); }

// The force and the energy from K against the tetrahedra's points, P1 and P2.
TEST(ContinuumFe, InternalForceIsTheBilinearFormOfThePoints) {
  for (int order : {1, 2})
    expect_force_is_the_points_bilinear_form(
        *make_continuum_solver("fe", settings("unit_cube.geo", 0.3, order, Material::isotropic(1e3, 0.3, 1.0))));
}

TEST(ContinuumFe, InterpolationOperatorReproducesAffineFields) {
  for (int order : {1, 2}) {
    auto s = make_continuum_solver("fe", settings("unit_cube.geo", 0.4, order, Material::isotropic(1, 0.3, 1)));
    std::vector<Vec3> pts;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> uni(0, 1);
    for (int i = 0; i < 200; ++i) pts.push_back({uni(rng), uni(rng), uni(rng)});
    pts.push_back({1, 1, 1});
    pts.push_back({0, 0.5, 1});
    const InterpolationOperator N = s->interpolation(pts);
    Eigen::VectorXd ux(s->num_nodes()), uy(s->num_nodes()), uz(s->num_nodes());
    for (int n = 0; n < s->num_nodes(); ++n) {
      const Vec3 u = affine(s->nodes()[n]);
      ux[n] = u.x, uy[n] = u.y, uz[n] = u.z;
    }
    const Eigen::VectorXd ix = N * ux, iy = N * uy, iz = N * uz;
    const Eigen::VectorXd one = N * Eigen::VectorXd::Ones(s->num_nodes());
    for (size_t p = 0; p < pts.size(); ++p) {
      const Vec3 e = affine(pts[p]);
      EXPECT_NEAR(one[p], 1.0, 1e-13);
      EXPECT_NEAR(ix[p], e.x, 1e-15);
      EXPECT_NEAR(iy[p], e.y, 1e-15);
      EXPECT_NEAR(iz[p], e.z, 1e-15);
    }
    EXPECT_THROW(s->interpolation({{1.1, 0.5, 0.5}}), InputError);
  }
}

TEST(ContinuumFe, WeightedLumpedMassIntegratesAlphaRho) {
  for (int order : {1, 2}) {
    auto s = make_continuum_solver("fe", settings("unit_cube.geo", 0.4, order, Material::isotropic(1, 0.3, 2.0)));
    double m = 0;
    for (double mi : s->lumped_mass()) {
      EXPECT_GT(mi, 0.0);
      m += mi;
    }
    EXPECT_NEAR(m, 2.0, 1e-12);
    s->set_weight([](const Vec3& x) { return x.x; });  // int_cube rho x = 1
    m = 0;
    for (double mi : s->lumped_mass()) m += mi;
    EXPECT_NEAR(m, 1.0, 1e-12);
    if (order == 1) {
      // P1's masses are row sums, m_I = int alpha rho N_I; with sum_I N_I x_I = x the first
      // moment sum_I m_I x_I is int rho x^2 = 2/3 (the degree-2 rule is exact for a linear alpha).
      // Equal shares of each element's int alpha rho would give the elements' centroids instead.
      const auto& masses = s->lumped_mass();
      double moment = 0;
      for (int n = 0; n < s->num_nodes(); ++n) moment += masses[static_cast<std::size_t>(n)] * s->nodes()[n].x;
      EXPECT_NEAR(moment, 2.0 / 3.0, 1e-12);
    }
    // The weight also scales the strain energy: alpha = 1/2 halves it.
    for (int n = 0; n < s->num_nodes(); ++n) s->displacement()[3 * n] = 1e-3 * s->nodes()[n].x;
    s->set_weight([](const Vec3&) { return 1.0; });
    const double e1 = s->strain_energy();
    s->set_weight([](const Vec3&) { return 0.5; });
    EXPECT_NEAR(s->strain_energy(), 0.5 * e1, 1e-14 * e1);
  }
}

// Random velocities on every dof excite the top mode: at 0.9 of the critical step the energy
// stays within velocity Verlet's oscillation about its shadow (bound: 1 + 1.5x the measured
// excess of max E / E_0 over 1, per method), and 10 % above the step the top mode blows up (the estimate
// is not needlessly small). fe P1, P2 and natural neighbours alike.
TEST(ContinuumFe, ExplicitStableBelowCriticalStepAndUnstableAbove) {
  for (const auto& [method, order, bound] : {std::tuple{"fe", 1, 1.31}, {"fe", 2, 1.125}, {"nem", 1, 1.145}}) {
    const double below = energy_growth(method, order, 0.9, 1500), above = energy_growth(method, order, 1.1, 1500);
    std::printf("%s P%d: max E / E_0 %.4g at 0.9 dt_c, %.3g at 1.1 dt_c\n", method, order, below, above);
    EXPECT_LT(below, bound) << method << " P" << order;
    EXPECT_GT(above, 1e6) << method << " P" << order;
  }
}

// The critical step against the dense eigenproblem: K column by column from the internal force
// of unit displacements (small kinematics: f_int = K u), A = M^-1/2 K M^-1/2, omega_max^2 its
// largest eigenvalue by Eigen's dense solver, dt_c = 2 / omega_max. The Lanczos estimate stops
// within 1e-6 of an eigenvalue and returns it from above, so dt_c lies in [1 - 1e-6, 1) of the
// dense one (measured: 0.9999997 to 0.999999998); fe P1, P2 and natural neighbours, with and
// without damping.
TEST(ContinuumFe, CriticalStepIsTheDenseEigenproblems) {
  for (const auto& [method, order] : {std::pair{"fe", 1}, {"fe", 2}, {"nem", 1}}) {
    auto s = make_continuum_solver(method, settings("unit_cube.geo", 0.5, order, Material::isotropic(3.0, 0.3, 2.0)));
    const auto n = static_cast<Eigen::Index>(s->dof_mass().size());
    Eigen::MatrixXd A(n, n);
    Field u(static_cast<std::size_t>(n), 0.0), f;
    for (Eigen::Index j = 0; j < n; ++j) {
      u[static_cast<std::size_t>(j)] = 1.0;
      s->internal_force(u, f);
      u[static_cast<std::size_t>(j)] = 0.0;
      for (Eigen::Index i = 0; i < n; ++i)
        A(i, j) = f[static_cast<std::size_t>(i)] / std::sqrt(s->dof_mass()[static_cast<std::size_t>(i)] *
                                                            s->dof_mass()[static_cast<std::size_t>(j)]);
    }
    const double omega_max = std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly).eigenvalues()(n - 1));
    for (double damping : {0.0, 0.3 * omega_max}) {
      s->set_damping(damping);
      // The damped step (common/damped_step.hpp) with c' = c / omega_max: (sqrt(c'^2 + 4) - c') / omega_max
      const double c = damping / omega_max, dense = (std::sqrt(c * c + 4.0) - c) / omega_max;
      const double ratio = s->critical_time_step() / dense;
      std::printf("%s P%d, %lld dofs, damping %.2g omega_max: dt_c / dense %.9f\n", method, order, static_cast<long long>(n),
                  c, ratio);
      // From above: below the dense step by the residual bound (measured 2e-9 to 3e-7), not by
      // the dense solver's round-off (~1e-14).
      EXPECT_LE(ratio, 1.0 - 1e-10) << method << " P" << order;
      EXPECT_GE(ratio, 1.0 - 1e-6) << method << " P" << order;
    }
  }
}

TEST(ContinuumFe, BarWaveFrontSpeed) {
  // nu = 0: the bar's longitudinal wave speed is sqrt(E / rho) for any cross-section; with a
  // share f of the mass carried along the bar (Material::inertia), sqrt(E / (f rho)).
  const double E = 2.0, rho = 0.5, v0 = 1e-3;
  for (const auto& [order, share] : {std::pair{1, 1.0}, {2, 1.0}, {1, 0.25}}) {
    Material material = Material::isotropic(E, 0.0, rho);
    material.inertia = {share, 1.0, 1.0};
    const double c = std::sqrt(E / (share * rho));
    auto s = make_continuum_solver("fe", settings("bar.geo", order == 1 ? 0.02 : 0.025, order, material));
    s->fix("left", {true, false, false}, [&](const Vec3&, double t) { return Vec3{v0 * t, 0, 0}; });
    s->compute_forces();
    const double dt = 0.9 * s->critical_time_step();
    std::vector<Vec3> line;
    for (int i = 0; i <= 2000; ++i) line.push_back({i / 2000.0, 0.05, 0.05});
    const InterpolationOperator N = s->interpolation(line);
    auto front = [&]() {
      Eigen::VectorXd vx(s->num_nodes());
      for (int n = 0; n < s->num_nodes(); ++n) vx[n] = s->velocity()[3 * n];
      const Eigen::VectorXd v = N * vx;
      for (int i = static_cast<int>(line.size()) - 1; i > 0; --i)
        if (v[i - 1] >= 0.5 * v0) {  // linear interpolation of the half-height crossing
          const double f = (v[i - 1] - 0.5 * v0) / (v[i - 1] - v[i]);
          return line[i - 1].x + f * (line[i].x - line[i - 1].x);
        }
      return 0.0;
    };
    const double t1 = 0.25 / c, t2 = 0.75 / c;
    while (s->time() < t1) s->step(std::min(dt, t1 - s->time()));
    const double x1 = front();
    while (s->time() < t2) s->step(std::min(dt, t2 - s->time()));
    const double x2 = front();
    EXPECT_NEAR((x2 - x1) / (t2 - t1), c, 0.02 * c) << "P" << order << ", inertia share " << share;
  }
}

// A still support (fix without a function) is skipped by the steps: it must step as the same
// support given as a zero motion, to the bit, from a pre-strained start with the other end
// driven (so the moving support's imposition and work still run, and close the balance), and
// its dofs must stay at u0 with zero velocity; fix() stops a held dof that was moving.
TEST(ContinuumFe, AStillSupportStepsAsAZeroMotionToTheBit) {
  const double eps = 1e-3, v0 = 2e-3;
  std::unique_ptr<ContinuumSolver> runs[2];
  continuum::Field u0;
  double e0 = 0.0;
  for (int still = 0; still < 2; ++still) {
    auto& s = runs[still];
    s = make_continuum_solver("fe", settings("bar.geo", 0.05, 2, Material::isotropic(2.0, 0.25, 0.5)));
    u0.assign(3 * static_cast<std::size_t>(s->num_nodes()), 0.0);
    for (int n = 0; n < s->num_nodes(); ++n) u0[3 * static_cast<std::size_t>(n)] = eps * (s->nodes()[n].x + 0.5);  // held end off 0
    s->set_initial_displacement(u0);
    if (still) {
      std::fill(s->velocity().begin(), s->velocity().end(), 0.25);
      s->fix("left", {true, true, true});
      for (int d = 0; d < 3 * s->num_nodes(); ++d)
        ASSERT_EQ(s->velocity()[static_cast<std::size_t>(d)], s->is_fixed(d) ? 0.0 : 0.25) << d;
      std::fill(s->velocity().begin(), s->velocity().end(), 0.0);
    } else
      s->fix("left", {true, true, true}, [](const Vec3&, double) { return Vec3{}; });
    s->fix("right", {true, false, false}, [&](const Vec3&, double t) { return Vec3{v0 * t, 0, 0}; });
    s->compute_forces();
    e0 = s->kinetic_energy() + s->strain_energy();
    const double dt = 0.9 * s->critical_time_step();
    for (int i = 0; i < 200; ++i) s->step(dt);
  }
  const ContinuumSolver& still = *runs[1];
  EXPECT_EQ(still.displacement(), runs[0]->displacement());
  EXPECT_EQ(still.velocity(), runs[0]->velocity());
  EXPECT_EQ(still.external_work(), runs[0]->external_work());
  EXPECT_NE(still.external_work(), 0.0);  // the driven end's work is summed
  // The balance E - E0 = W (the driven end's work), to velocity Verlet's error at 0.9 of the
  // critical step: 6.1e-4 of E0 + W measured; bound 2e-3.
  const double balance = still.kinetic_energy() + still.strain_energy() - e0 - still.external_work();
  EXPECT_LT(std::abs(balance), 2e-3 * (e0 + still.external_work()));
  for (int n = 0; n < still.num_nodes(); ++n)
    if (still.nodes()[n].x < 1e-12)
      for (int c = 0; c < 3; ++c) {
        const std::size_t d = 3 * static_cast<std::size_t>(n) + static_cast<std::size_t>(c);
        EXPECT_EQ(still.displacement()[d], u0[d]);
        EXPECT_EQ(still.velocity()[d], 0.0);
      }
}

// A pre-strained start (initial_strain in a case): the essential conditions prescribe their
// g on top of the initial displacement, set before or after them, so a held end stays where it
// starts and a driven end moves from there (as the DEM's conditions move DEs). The uniform
// strain with both ends held is then the static state: no node moves.
TEST(ContinuumFe, EssentialConditionsActOnTopOfTheInitialDisplacement) {
  const double eps = 1e-3, v0 = 2e-3;
  auto s = make_continuum_solver("fe", settings("bar.geo", 0.05, 1, Material::isotropic(2.0, 0.0, 0.5)));
  s->fix("left", {true, true, true}, [](const Vec3&, double) { return Vec3{}; });
  continuum::Field u0(3 * s->num_nodes(), 0.0);
  for (int n = 0; n < s->num_nodes(); ++n) u0[3 * n] = eps * s->nodes()[n].x;
  s->set_initial_displacement(u0);
  s->fix("right", {true, false, false}, [&](const Vec3&, double t) { return Vec3{v0 * t, 0, 0}; });
  s->compute_forces();
  const double dt = 0.9 * s->critical_time_step();
  // Eight steps: an explicit step reaches one element further, so the left half (ten elements
  // of 0.05) cannot yet feel the driven end; it must stay on eps x to round-off.
  for (int i = 0; i < 8; ++i) s->step(dt);
  const double t = s->time();
  double interior_max = 0.0;
  for (int n = 0; n < s->num_nodes(); ++n) {
    const double x = s->nodes()[n].x, ux = s->displacement()[3 * n];
    if (x < 1e-12) EXPECT_NEAR(ux, eps * x, 1e-15);                 // held at its start
    else if (x > 1 - 1e-12) {  // moved from its start, at the velocity that reaches each step's value
      EXPECT_NEAR(ux, eps * x + v0 * t, 1e-15);
      EXPECT_NEAR(s->velocity()[3 * n], v0, 1e-12 * v0);  // measured 3.7e-15 v0
    }
    else if (x < 0.5) interior_max = std::max(interior_max, std::abs(ux - eps * x));
  }
  EXPECT_LT(interior_max, 1e-12 * eps);
}
