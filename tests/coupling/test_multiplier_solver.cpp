// SPDX-License-Identifier: GPL-3.0-or-later
// MultiplierSolver on hand-built operators: the projection onto ker G against its closed form,
// and a row whose dofs are all held (empty row, multiplier 0) beside rows that are not; with
// each backend (our LDL^T, PETSc's direct and an iterative PETSc solve).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>

#include "common/error.hpp"
#include "common/parallel.hpp"
#include "coupling/multiplier_solver.hpp"
#include "support/omp_threads.hpp"

using namespace arlequin;
using namespace arlequin::coupling;

namespace {

// Fine mediator with every DE on a node: G_d = S, G_c = -S (N = I), S = diag(w). Row i then
// reads w_i (vd_i - vc_i) = 0, A_ii = w_i^2 (md_i + mc_i), and the projection has the closed form
//   lambda_i = (vd_i - vc_i) / (w_i (md_i + mc_i)),  vd_i, vc_i -> (md_i^-1 vd_i + mc_i^-1 vc_i) / (md_i^-1 + mc_i^-1)
// (momentum-weighted mean), with md, mc the inverse masses.
CouplingOperators one_to_one(const std::vector<double>& w) {
  const int n = static_cast<int>(w.size());
  CouplingOperators ops;
  for (int i = 0; i < n; ++i) ops.particles.push_back(static_cast<std::uint32_t>(i));
  ops.N.resize(n, n);
  ops.Gd.resize(n, n);
  ops.Gc.resize(n, n);
  for (int i = 0; i < n; ++i) {
    ops.N.insert(i, i) = 1.0;
    ops.Gd.insert(i, i) = w[i];
    ops.Gc.insert(i, i) = -w[i];
  }
  return ops;
}

// Velocities of one_to_one's four rows (DEs and nodes), mixed in sign and size.
void four_row_velocities(Matrix3& vd, Matrix3& vc) {
  vd.resize(4, 3);
  vc.resize(4, 3);
  vd << 1, 2, 3, -1, 0.5, 2, 4, -3, 1, 0.2, 0.3, -0.7;
  vc << -2, 1, 0, 3, 1.5, -1, 2, 2, 2, -0.4, 0.9, 0.1;
}

// nullopt: our LDL^T; a string: PETSc with these options.
const std::optional<std::string> backends[] = {std::nullopt, std::string(), std::string("-ksp_type cg -pc_type jacobi -ksp_rtol 1e-14")};

}  // namespace

TEST(CouplingMultiplierSolver, ProjectionIsTheMomentumWeightedMeanAndAHeldRowIsEmpty) {
  for (const auto& backend : backends) {
  const std::vector<double> w{0.5, 1.0, 2.0, 0.25};
  const CouplingOperators ops = one_to_one(w);
  // Row 0: DE and node held (inverse masses 0): empty. Row 2: DE held, node free. Rows 1, 3 free.
  const std::vector<double> md{0.0, 2.0, 0.0, 4.0};
  std::vector<double> mc;  // per dof; rows 1 and 3 carry different masses per component
  const double node_inv[4] = {0.0, 1.0, 3.0, 0.5};
  for (int i = 0; i < 4; ++i)
    for (int c = 0; c < 3; ++c) mc.push_back(node_inv[i] * (c == 1 && i != 0 ? 2.0 : 1.0));
  const MultiplierSolver solver(ops, md, mc, backend);
  EXPECT_EQ(solver.systems(), 2) << solver.backend();  // y differs from x, z reuses x's system
  EXPECT_EQ(solver.backend(), !backend ? "LDL^T" : backend->empty() ? "PETSc preonly + cholesky" : "PETSc cg + jacobi");

  Matrix3 vd, vc, dd, dc, lambda;
  four_row_velocities(vd, vc);
  const Matrix3 vd0 = vd, vc0 = vc;
  solver.project(vd, vc, dd, dc, lambda);
  for (int i = 0; i < 4; ++i)
    for (int c = 0; c < 3; ++c) {
      const double a = md[i], b = mc[3 * i + c];
      if (a + b == 0.0) {  // the empty row: nothing moves, no multiplier
        EXPECT_EQ(lambda(i, c), 0.0);
        EXPECT_EQ(vd(i, c), vd0(i, c));
        EXPECT_EQ(vc(i, c), vc0(i, c));
        continue;
      }
      EXPECT_NEAR(lambda(i, c), (vd0(i, c) - vc0(i, c)) / (w[i] * (a + b)), 1e-12) << i << c;
      // A held side keeps its velocity (inverse mass 0 means infinite mass in the mean).
      const double mean = a == 0.0 ? vd0(i, c) : b == 0.0 ? vc0(i, c) : (vd0(i, c) / a + vc0(i, c) / b) / (1 / a + 1 / b);
      EXPECT_NEAR(vd(i, c), mean, 1e-12) << i << c;
      EXPECT_NEAR(vc(i, c), mean, 1e-12) << i << c;
      EXPECT_NEAR(dd(i, c), vd0(i, c) - vd(i, c), 1e-12);
      EXPECT_NEAR(dc(i, c), vc0(i, c) - vc(i, c), 1e-12);
    }
  }
}

TEST(CouplingMultiplierSolver, ARowThatNothingCanMeetIsNotSilentlyAccepted) {
  // Two rows over one free DE and no node: A = m [w0^2, w0 w1; w0 w1, w1^2] is singular (rank 1).
  CouplingOperators ops;
  ops.particles = {0};
  ops.N.resize(1, 1);
  ops.Gd.resize(2, 1);
  ops.Gc.resize(2, 1);
  ops.Gd.insert(0, 0) = 1.0;
  ops.Gd.insert(1, 0) = 2.0;
  // Refused at set-up by every backend: an iterative one would solve G v = A lambda here
  // without complaint (r lies in A's range), so the check is ours, not the backend's.
  for (const auto& backend : backends)
    EXPECT_THROW(MultiplierSolver(ops, {1.0}, {1.0, 1.0, 1.0}, backend), RunError) << (backend ? "PETSc " + *backend : "LDL^T");
}

namespace {
struct SharedNodes {
  CouplingOperators fine;
  std::vector<double> md, mc;
};
// np DEs on nn nodes, fine mediator, DE p interpolated from the three nodes reach(p) with
// positive weights summing to 1; DE masses ~0.1 mg, node masses ~5 mg.
template <class Reach>
SharedNodes fine_operators(int np, int nn, Reach&& reach) {
  CouplingOperators fine;
  fine.settings.mediator = Mediator::fine;
  fine.N.resize(np, nn);
  fine.Gd.resize(np, np);
  fine.Gc.resize(np, nn);
  std::vector<double> md(np), mc(3 * nn);
  for (int p = 0; p < np; ++p) {
    fine.particles.push_back(static_cast<std::uint32_t>(p));
    const double w = 1e-9 * (1.0 + 0.5 * std::sin(p));  // m^3, a DE's share of the overlap
    const double a = 0.2 + 0.1 * std::cos(3.0 * p), b = 0.3;
    const std::array<int, 3> nodes = reach(p);
    const double N[3] = {a, b, 1.0 - a - b};
    fine.Gd.insert(p, p) = w;
    for (int k = 0; k < 3; ++k) {
      fine.N.insert(p, nodes[k]) = N[k];
      fine.Gc.insert(p, nodes[k]) = -w * N[k];
    }
    md[p] = 1.0 / (1e-7 * (1.0 + 0.3 * std::cos(p)));
  }
  for (int d = 0; d < 3 * nn; ++d) mc[d] = 1.0 / (5e-6 * (1.0 + 0.1 * (d / 3 % 8)));
  return {fine, md, mc};
}
// 30 DEs on 8 nodes, DE p on nodes p, p + 3 and p + 5 (mod 8); node 2 held along y.
SharedNodes shared_nodes() {
  SharedNodes s = fine_operators(30, 8, [](int p) { return std::array<int, 3>{p % 8, (p + 3) % 8, (p + 5) % 8}; });
  s.mc[3 * 2 + 1] = 0.0;
  return s;
}

// Velocities of np DEs and nn nodes, mixed in sign and size: z of DE p is 0.5 - drift p, x and y
// of node i are (scale i, -2 scale i).
void mixed_velocities(Eigen::Index np, Eigen::Index nn, double drift, double scale, Matrix3& vd, Matrix3& vc) {
  vd.resize(np, 3);
  vc.resize(nn, 3);
  for (Eigen::Index p = 0; p < np; ++p) vd.row(p) << std::sin(0.7 * p), std::cos(1.3 * p), 0.5 - drift * p;
  for (Eigen::Index i = 0; i < nn; ++i) vc.row(i) << scale * i, -2.0 * scale * i, std::sin(i);
}

// A solver's projection of (vd, vc): the projected velocities and the multipliers.
struct Projected {
  Matrix3 vd, vc, lambda;
};
Projected projected(const MultiplierSolver& solver, const Matrix3& vd, const Matrix3& vc) {
  Projected out{vd, vc, {}};
  Matrix3 dd, dc;
  solver.project(out.vd, out.vc, dd, dc, out.lambda);
  return out;
}
}  // namespace

// The fine mediator (G_d = W diagonal, G_c = -W N) is solved by the Woodbury form; the same
// matrices through the general LDL^T (the operators marked coarse, which that path does not
// look at) give the same multipliers to round-off, both project onto ker G, and a held node
// (inverse mass 0 in one component) keeps its velocity (shared_nodes above).
TEST(CouplingMultiplierSolver, FineMediatorIsSolvedByTheWoodburyFormAsByTheFactor) {
  const auto [fine, md, mc] = shared_nodes();
  const int np = fine.num_particles(), nn = static_cast<int>(fine.Gc.cols());
  CouplingOperators general = fine;
  general.settings.mediator = Mediator::coarse;
  const MultiplierSolver woodbury(fine, md, mc, std::nullopt), factor(general, md, mc, std::nullopt);
  EXPECT_EQ(factor.backend(), "LDL^T");
  EXPECT_EQ(woodbury.backend().rfind("diagonal + low rank (Woodbury)", 0), 0u) << woodbury.backend();
  EXPECT_EQ(woodbury.systems(), 2);  // y differs from x, z reuses x's

  Matrix3 vd, vc;
  mixed_velocities(np, nn, 0.03, 0.1, vd, vc);
  const Projected w = projected(woodbury, vd, vc), f = projected(factor, vd, vc);
  EXPECT_LT((w.lambda - f.lambda).norm(), 1e-10 * f.lambda.norm());
  EXPECT_LT((w.vd - f.vd).norm(), 1e-10 * vd.norm());
  Matrix3 residual;
  woodbury.residual(w.vd, w.vc, residual);
  EXPECT_LT(residual.norm(), 1e-12 * 1e-9 * vd.norm());  // G v = 0, G's scale being w ~ 1e-9
  EXPECT_EQ(w.vc(2, 1), vc(2, 1));                      // the held dof
}

// The impulses a projection returns are G_d^T lambda and G_c^T lambda, a held dof's reaction
// included (node 2 along y): the Woodbury form reads them from the corrections (C^-1 dc where a
// node moves), the general factor from its products; both against the products of the operators.
TEST(CouplingMultiplierSolver, TheImpulsesAreGTransposedLambdaWithTheHeldDofs) {
  const auto [fine, md, mc] = shared_nodes();
  CouplingOperators general = fine;
  general.settings.mediator = Mediator::coarse;
  const MultiplierSolver woodbury(fine, md, mc, std::nullopt), factor(general, md, mc, std::nullopt);
  for (const MultiplierSolver* solver : {&woodbury, &factor}) {
    Matrix3 vd, vc, dd, dc, lambda;
    mixed_velocities(fine.num_particles(), fine.Gc.cols(), 0.03, 0.1, vd, vc);
    MultiplierSolver::Impulse impulse;
    solver->project(vd, vc, dd, dc, lambda, &impulse);
    const Matrix3 dem = fine.Gd.transpose() * lambda, continuum = fine.Gc.transpose() * lambda;
    std::printf("[impulse %s] relative error DEs %.1e, nodes %.1e\n", solver->backend().substr(0, 5).c_str(),
                (impulse.dem - dem).norm() / dem.norm(), (impulse.continuum - continuum).norm() / continuum.norm());
    // Measured: 0 for the factor, 3e-15 of the nodes' for the Woodbury form (C^-1 dc): 30 times below.
    EXPECT_LT((impulse.dem - dem).norm(), 1e-13 * dem.norm()) << solver->backend();
    EXPECT_LT((impulse.continuum - continuum).norm(), 1e-13 * continuum.norm()) << solver->backend();
    EXPECT_GT(std::abs(continuum(2, 1)), 1e-3 * continuum.norm());  // the held dof's reaction is there to check
    EXPECT_NEAR(impulse.continuum(2, 1), continuum(2, 1), 1e-13 * continuum.norm()) << solver->backend();
  }
}

// A rate scales what a projection returns, not what it projects: the projected velocities are
// the same to the bit, the corrections, multipliers and the DEs' impulses are rate times those
// of rate 1 to the bit (each scaled once computed), and the nodes' impulses to round-off (a held
// dof's is a sum of the scaled multipliers), in the Woodbury form and the general factor.
TEST(CouplingMultiplierSolver, ARateScalesTheCorrectionsMultipliersAndImpulsesOnly) {
  const auto [fine, md, mc] = shared_nodes();
  CouplingOperators general = fine;
  general.settings.mediator = Mediator::coarse;
  const MultiplierSolver woodbury(fine, md, mc, std::nullopt), factor(general, md, mc, std::nullopt);
  const double rate = 2.0 / 3.1e-9;  // a half step's 2/dt
  for (const MultiplierSolver* solver : {&woodbury, &factor}) {
    Matrix3 vd, vc;
    mixed_velocities(fine.num_particles(), fine.Gc.cols(), 0.03, 0.1, vd, vc);
    Matrix3 vd1 = vd, vc1 = vc, vdr = vd, vcr = vc, dd1, dc1, lambda1, ddr, dcr, lambdar;
    MultiplierSolver::Impulse impulse1, impulser;
    solver->project(vd1, vc1, dd1, dc1, lambda1, &impulse1);
    solver->project(vdr, vcr, ddr, dcr, lambdar, &impulser, rate);
    const std::string name = solver->backend().substr(0, 5);
    EXPECT_EQ(vdr, vd1) << name;
    EXPECT_EQ(vcr, vc1) << name;
    EXPECT_GT(dd1.norm(), 1e-3 * vd.norm()) << name;  // there is a correction to scale
    EXPECT_EQ(ddr, Matrix3(rate * dd1)) << name;
    EXPECT_EQ(dcr, Matrix3(rate * dc1)) << name;
    EXPECT_EQ(lambdar, Matrix3(rate * lambda1)) << name;
    EXPECT_EQ(impulser.dem, Matrix3(rate * impulse1.dem)) << name;
    EXPECT_LT((impulser.continuum - rate * impulse1.continuum).norm(), 1e-15 * rate * impulse1.continuum.norm()) << name;
  }
}

// Two bodies coupled apart (the DCB's two arms): K falls into two blocks, its factor's
// elimination forest into two trees of 1500 columns, and the Woodbury form solves them as two
// independent parts, on the threads. The multipliers are the general factor's to round-off, G v
// = 0 after the projection, and the bits are the same on 1 and 2 threads. Sized so that the
// solves and the per-row loops run on the threads (their factors' non-zeros and the rows above
// parallel_threshold): at 400 columns a body everything ran on one thread either way.
TEST(CouplingMultiplierSolver, TwoBodiesAreSolvedInTwoIndependentParts) {
  const int bodies = 2, nodes = 1500, des = 3400, np = bodies * des, nn = bodies * nodes;
  static_assert(bodies * des > arlequin::parallel_threshold);
  const auto [fine, md, mc] = fine_operators(np, nn, [](int p) {  // a chain through the body's nodes
    const int first = (p / des) * nodes, k = (p % des) * 7 % nodes;
    return std::array<int, 3>{first + k, first + (k + 1) % nodes, first + (k + 2) % nodes};
  });
  CouplingOperators general = fine;
  general.settings.mediator = Mediator::coarse;  // the general factor (see above)
  const MultiplierSolver woodbury(fine, md, mc, std::nullopt), factor(general, md, mc, std::nullopt);
  EXPECT_NE(woodbury.backend().find("in 2 independent parts"), std::string::npos) << woodbury.backend();

  Matrix3 vd, vc;
  mixed_velocities(np, nn, 0.0003, 0.01, vd, vc);
  Projected w[2];
  for (int threads : {1, 2}) {
#ifdef _OPENMP
    const test::OmpThreads scope(threads);
#endif
    w[threads - 1] = projected(woodbury, vd, vc);
  }
  EXPECT_EQ(w[0].lambda, w[1].lambda);
  EXPECT_EQ(w[0].vd, w[1].vd);
  EXPECT_EQ(w[0].vc, w[1].vc);
  const Matrix3 lambda_f = projected(factor, vd, vc).lambda;
  EXPECT_LT((w[0].lambda - lambda_f).norm(), 1e-10 * lambda_f.norm());
  Matrix3 residual;
  woodbury.residual(w[0].vd, w[0].vc, residual);
  EXPECT_LT(residual.norm(), 1e-12 * 1e-9 * vd.norm());  // G v = 0, G's scale being w ~ 1e-9
}

// Supernodes: the nodes fall into cliques of 1 to 19 nodes (every pair of a clique shares a DE,
// so K is dense on each), each clique tied to the next by a DE on both, so that the factor holds
// dense runs of columns of every size up to and beyond the widest supernode a solve takes (8), and
// columns with shared rows below their triangle. The Woodbury form's multipliers, which go through
// the supernodal solves, are PETSc's direct solve's of the same A (the general form, solved by
// PETSc) to round-off, and G v = 0 after the projection.
TEST(CouplingMultiplierSolver, SupernodesAreSolvedAsPetscSolvesTheSameSystem) {
  std::vector<std::array<int, 3>> reach;
  int first = 0;
  for (int size = 1; size < 20; ++size) {
    for (int a = 0; a < size; ++a)
      for (int b = a + 1; b < size; ++b) reach.push_back({first + a, first + b, first + (a + b + 1) % size});
    if (size == 1) reach.push_back({first, first, first});
    if (size < 19) reach.push_back({first + size - 1, first + size, first});  // to the next clique
    first += size;
  }
  const int np = static_cast<int>(reach.size()), nn = first;
  const auto [fine, md, mc] = fine_operators(np, nn, [&](int p) { return reach[static_cast<std::size_t>(p)]; });
  CouplingOperators general = fine;
  general.settings.mediator = Mediator::coarse;  // the general form, here solved by PETSc
  const MultiplierSolver woodbury(fine, md, mc, std::nullopt), petsc(general, md, mc, std::string());
  EXPECT_NE(woodbury.backend().find("the widest of all 8 columns"), std::string::npos) << woodbury.backend();

  Matrix3 vd, vc;
  mixed_velocities(np, nn, 0.003, 0.01, vd, vc);
  const Projected w = projected(woodbury, vd, vc), p = projected(petsc, vd, vc);
  // Measured: 6.3e-16 and 2.9e-16 (round-off); the bounds a few hundred and a few ten times that.
  EXPECT_LT((w.lambda - p.lambda).norm(), 1e-13 * p.lambda.norm());
  Matrix3 residual;
  woodbury.residual(w.vd, w.vc, residual);
  EXPECT_LT(residual.norm(), 1e-14 * 1e-9 * vd.norm());  // G v = 0, G's scale being w ~ 1e-9
}

// A held dof at a node no row reaches (a load strip far from the overlap) does not split the
// components' systems: A reads the continuum's inverse masses only where G_c has entries. With a
// ninth node, held along z and reached by no DE, x and z still share one system (two in all, as
// without it), and the multipliers are those of the eight-node operators to the bit.
TEST(CouplingMultiplierSolver, AHeldNodeNoRowReachesLeavesTheSystemsShared) {
  const auto [fine, md, mc] = shared_nodes();
  const int np = fine.num_particles(), nn = static_cast<int>(fine.Gc.cols());
  CouplingOperators wider = fine;
  wider.N.conservativeResize(np, nn + 1);
  wider.Gc.conservativeResize(np, nn + 1);
  std::vector<double> mc_wider = mc;
  mc_wider.insert(mc_wider.end(), {mc[0], mc[1], 0.0});  // node 8: held along z
  for (const bool woodbury : {true, false}) {
    CouplingOperators a = fine, b = wider;
    if (!woodbury) a.settings.mediator = b.settings.mediator = Mediator::coarse;  // the general factor
    const MultiplierSolver eight(a, md, mc, std::nullopt), nine(b, md, mc_wider, std::nullopt);
    EXPECT_EQ(nine.systems(), 2) << nine.backend();
    Matrix3 vd, vc8, vc9(nn + 1, 3);
    mixed_velocities(np, nn, 0.03, 0.1, vd, vc8);
    vc9.topRows(nn) = vc8;
    vc9.row(nn) << 1.0, 2.0, 3.0;
    Matrix3 vd8 = vd, vd9 = vd, dd, dc, lambda8, lambda9;
    eight.project(vd8, vc8, dd, dc, lambda8);
    nine.project(vd9, vc9, dd, dc, lambda9);
    EXPECT_EQ(lambda9, lambda8) << nine.backend();
    EXPECT_EQ(vc9.row(nn), Eigen::RowVector3d(1.0, 2.0, 3.0)) << nine.backend();  // no row reaches it
  }
}

// Partial ties (CouplingOperators::tied): in a component a row leaves free there is no
// multiplier and both velocities stay; in the held ones they meet at the momentum-weighted mean
// (one_to_one's closed form). The masses are the same in x, y and z, the ties are not: three
// systems. Through the general factor with each backend, and the Woodbury form (fine mediator).
TEST(CouplingMultiplierSolver, AFreeComponentKeepsItsVelocitiesAndTheHeldOnesMeet) {
  const std::vector<double> w{0.5, 1.0, 2.0, 0.25}, md{1.0, 2.0, 0.5, 4.0};
  std::vector<double> mc;
  for (int i = 0; i < 4; ++i)
    for (int c = 0; c < 3; ++c) mc.push_back(0.5 + 0.25 * i);
  const bool held[4][3] = {{true, false, true}, {false, true, true}, {false, false, true}, {true, true, true}};
  for (int pass = 0; pass < 4; ++pass) {
    CouplingOperators ops = one_to_one(w);
    const bool woodbury = pass == 3;
    ops.settings.mediator = Mediator::fine;
    std::vector<std::array<bool, 3>> components(4);
    for (int i = 0; i < 4; ++i) components[i] = {held[i][0], held[i][1], held[i][2]};
    ops.tie_components(components);
    if (!woodbury) ops.settings.mediator = Mediator::coarse;  // the general factor, which does not look at it
    const MultiplierSolver solver(ops, md, mc, woodbury ? std::nullopt : backends[pass]);
    EXPECT_EQ(solver.systems(), 3) << solver.backend();
    EXPECT_EQ(solver.backend().rfind("diagonal + low rank (Woodbury)", 0) == 0, woodbury) << solver.backend();
    Matrix3 vd, vc, dd, dc, lambda, residual;
    four_row_velocities(vd, vc);
    const Matrix3 vd0 = vd, vc0 = vc;
    solver.project(vd, vc, dd, dc, lambda);
    for (int i = 0; i < 4; ++i)
      for (int c = 0; c < 3; ++c) {
        if (!held[i][c]) {
          EXPECT_EQ(lambda(i, c), 0.0) << pass << i << c;
          EXPECT_EQ(vd(i, c), vd0(i, c)) << pass << i << c;
          EXPECT_EQ(vc(i, c), vc0(i, c)) << pass << i << c;
          continue;
        }
        const double a = md[i], b = mc[3 * i + c];
        const double mean = (vd0(i, c) / a + vc0(i, c) / b) / (1 / a + 1 / b);
        EXPECT_NEAR(lambda(i, c), (vd0(i, c) - vc0(i, c)) / (w[i] * (a + b)), 1e-12) << pass << i << c;
        EXPECT_NEAR(vd(i, c), mean, 1e-12) << pass << i << c;
        EXPECT_NEAR(vc(i, c), mean, 1e-12) << pass << i << c;
      }
    solver.residual(vd0, vc0, residual);  // the free components are not part of the residual
    for (int i = 0; i < 4; ++i)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(residual(i, c) == 0.0, !held[i][c]) << i << c;
  }
  // Ties need a row per DE.
  CouplingOperators coarse = one_to_one(w);
  EXPECT_THROW(coarse.tie_components(std::vector<std::array<bool, 3>>(4, {true, true, false})), SettingError);

  // Nodes shared by held and free rows (shared_nodes): the Woodbury form leaves the free rows out
  // of its K as the general factor leaves them out of A; both give the same multipliers.
  auto [fine, md_s, mc_s] = shared_nodes();
  std::vector<std::array<bool, 3>> ties(static_cast<std::size_t>(fine.num_particles()));
  for (std::size_t p = 0; p < ties.size(); ++p) ties[p] = {p % 3 != 0, p % 3 != 1, true};
  fine.tie_components(ties);
  CouplingOperators general = fine;
  general.settings.mediator = Mediator::coarse;
  const MultiplierSolver woodbury(fine, md_s, mc_s, std::nullopt), factor(general, md_s, mc_s, std::nullopt);
  EXPECT_EQ(woodbury.backend().rfind("diagonal + low rank (Woodbury)", 0), 0u) << woodbury.backend();
  Matrix3 vd, vc;
  mixed_velocities(fine.num_particles(), fine.Gc.cols(), 0.03, 0.1, vd, vc);
  const Projected low_rank = projected(woodbury, vd, vc), f = projected(factor, vd, vc);
  EXPECT_LT((low_rank.lambda - f.lambda).norm(), 1e-10 * f.lambda.norm());
  EXPECT_LT((low_rank.vc - f.vc).norm(), 1e-10 * vc.norm());
  for (std::size_t p = 0; p < ties.size(); ++p)
    for (int c = 0; c < 3; ++c) {
      if (ties[p][static_cast<std::size_t>(c)]) continue;
      EXPECT_EQ(low_rank.vd(static_cast<Eigen::Index>(p), c), vd(static_cast<Eigen::Index>(p), c)) << p << c;
    }
}

// A row tied in no component whose DE is driven (inverse mass 0: a clamped DE on the
// continuum's clamped face, CoupledModel's untied prescribed rows) has no multiplier and needs no
// pivot of D: the Woodbury form still applies (it fell back to the general factor), gives the
// factor's multipliers, and leaves that DE's velocity alone.
TEST(CouplingMultiplierSolver, AnUntiedDrivenRowKeepsTheWoodburyForm) {
  auto [fine, md, mc] = shared_nodes();
  const int np = fine.num_particles(), nn = static_cast<int>(fine.Gc.cols()), driven = 4;
  md[driven] = 0.0;
  std::vector<std::array<bool, 3>> ties(static_cast<std::size_t>(np), {true, true, true});
  ties[driven] = {false, false, false};
  fine.tie_components(ties);
  CouplingOperators general = fine;
  general.settings.mediator = Mediator::coarse;
  const MultiplierSolver woodbury(fine, md, mc, std::nullopt), factor(general, md, mc, std::nullopt);
  EXPECT_EQ(woodbury.backend().rfind("diagonal + low rank (Woodbury)", 0), 0u) << woodbury.backend();
  Matrix3 vd, vc, residual;
  mixed_velocities(np, nn, 0.03, 0.1, vd, vc);
  const Projected w = projected(woodbury, vd, vc), f = projected(factor, vd, vc);
  EXPECT_LT((w.lambda - f.lambda).norm(), 1e-10 * f.lambda.norm());
  EXPECT_LT((w.vc - f.vc).norm(), 1e-10 * vc.norm());
  EXPECT_EQ(w.lambda.row(driven), Eigen::RowVector3d::Zero().eval());
  EXPECT_EQ(w.vd.row(driven), vd.row(driven));
  woodbury.residual(w.vd, w.vc, residual);
  EXPECT_LT(residual.norm(), 1e-12 * 1e-9 * vd.norm());
}
