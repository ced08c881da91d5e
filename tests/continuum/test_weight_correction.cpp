// SPDX-License-Identifier: GPL-3.0-or-later
// ContinuumSolver::correct_weights (the Arlequin overlap's consistent quadrature,
// coupling/coupled_model.hpp): the weighted gradient sums g_a = sum_q w_q grad_q N_a meet their targets,
// the weights stay positive, and nothing outside alpha < 1 moves.
#include <gtest/gtest.h>

#include <cmath>

#include "common/error.hpp"
#include "continuum_test_util.hpp"

using namespace arlequin;
using namespace arlequin::continuum;
using namespace arlequin::continuum::testing;

namespace {

// g_a read through the internal force: with nu = 0 and E = 1 the strain e_k e_k (u = x_k e_k)
// is the stress e_k e_k, whose weighted internal force at node a is e_k g_a[k].
std::vector<Vec3> weighted_gradients(const ContinuumSolver& s) {
  std::vector<Vec3> g(s.num_nodes());
  Field u(3 * s.num_nodes()), f;
  for (int k = 0; k < 3; ++k) {
    std::fill(u.begin(), u.end(), 0.0);
    for (int n = 0; n < s.num_nodes(); ++n) u[3 * n + k] = s.nodes()[n][k];
    s.internal_force(u, f);
    for (int n = 0; n < s.num_nodes(); ++n) g[n][k] = f[3 * n + k];
  }
  return g;
}

double largest_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double d = 0.0;
  for (std::size_t n = 0; n < a.size(); ++n) d = std::max(d, norm(a[n] - b[n]));
  return d;
}

// A ramp that reaches 1 at x = 0.7: the points beyond keep their weights.
double ramp(const Vec3& x) { return std::min(1.0, 0.3 + x.x); }

}  // namespace

TEST(ContinuumWeightCorrection, MeetsReachableTargetsWithPositiveWeights) {
  for (const std::string method : {"fe", "nem"}) {
    const ContinuumSettings set = settings("unit_cube.geo", 0.25, 1, Material::isotropic(1.0, 0.0, 1.0));
    auto s = make_continuum_solver(method, set);
    s->set_weight(ramp);
    const std::vector<double> before = s->point_weights(), mass = s->lumped_mass();
    const std::vector<Vec3> g0 = weighted_gradients(*s);
    double gauge = 0.0;
    for (const Vec3& v : g0) gauge = std::max(gauge, norm(v));

    // The targets of the same weights: nothing to change.
    std::vector<char> all(s->num_nodes(), 1);
    const auto none = s->correct_weights(g0, all);
    EXPECT_LT(none.largest_change, 1e-12) << method;

    // Targets that another weight with the same support reaches (so they can be met), every node
    // constrained: the rows of all nodes sum to zero (partition of unity), a dependent system.
    auto other = make_continuum_solver(method, set);
    other->set_weight([](const Vec3& x) { return ramp(x) < 1.0 ? ramp(x) * (1.0 + 0.3 * std::sin(7 * x.x + 3 * x.y + 5 * x.z)) : 1.0; });
    const std::vector<Vec3> target = weighted_gradients(*other);
    const auto c = s->correct_weights(target, all);
    EXPECT_GT(c.nodes, 0) << method;
    EXPECT_GT(c.largest_change, 1e-3) << method;
    EXPECT_GT(c.smallest_weight, 0.0) << method;
    EXPECT_LT(largest_difference(weighted_gradients(*s), target), 1e-11 * gauge) << method;
    for (std::size_t q = 0; q < before.size(); ++q) {
      if (ramp(s->point_positions()[q]) < 1.0) continue;
      EXPECT_EQ(s->point_weights()[q], before[q]) << method << " point " << q;
    }
    EXPECT_EQ(s->lumped_mass(), mass) << method;  // the mass is not the correction's business

    // Targets that contradict the partition of unity (their sum over all nodes is not the
    // weights' sum of gradients, zero) are refused.
    std::vector<Vec3> wrong = g0;
    wrong[0] += Vec3{1e-3 * gauge, 0, 0};
    const std::vector<double> corrected = s->point_weights();
    EXPECT_THROW(s->correct_weights(wrong, all), InputError) << method;
    EXPECT_EQ(s->point_weights(), corrected) << method;  // a refused correction changes nothing
  }
}
