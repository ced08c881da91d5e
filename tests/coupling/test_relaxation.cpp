// SPDX-License-Identifier: GPL-3.0-or-later
// Dynamic relaxation of a coupled state (CoupledModel::relax, which a move of a following band's
// start runs): it moves the displacements to the equilibrium of the target accelerations and
// gives back the motion, time and running sums it found.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "coupling_test_util.hpp"

using namespace arlequin;
using namespace arlequin::coupling;
using namespace arlequin::coupling::testing;

namespace {

// The bar of the tests below: four DE lines on [0, X2] (E = rho = 1, a = b = 1, nu = 0),
// coupled over [X1, X2] (linear weights) to the one-cell-thick mesh on [X1, L], held at x = L
// when `held`, its internal force every `substeps` steps.
constexpr double X1 = 20.0, X2 = 28.0, L = 80.0;
struct CoupledBar {
  std::unique_ptr<continuum::ContinuumSolver> cont;
  dem::DemModel dem;
  std::unique_ptr<CoupledModel> model;
};
std::unique_ptr<CoupledBar> coupled_bar(const std::string& mesh, bool held, int substeps = 1) {
  auto bar = std::make_unique<CoupledBar>();
  bar->cont = make_continuum("fe", mesh, 1.0, 0.0, 1.0);
  if (held) bar->cont->fix("xmax", {true, true, true}, [](const Vec3&, double) { return Vec3{}; });
  build_four_lines(bar->dem, static_cast<int>(X2) + 1, 1.0, 1.0, 1.0, 1.0);
  const OverlapZone zone = OverlapZone::box({{X1, -1, -1}, {X2, 2, 2}}, 0, true, {WeightShape::linear, 0.05, 0.5});
  CoupledOptions options;
  options.continuum_substeps = substeps;
  bar->model = std::make_unique<CoupledModel>(bar->dem, *bar->cont, zone, options);
  return bar;
}
std::string bar_mesh(const std::string& name) { return write_box_mesh(name, X1, static_cast<int>(L - X1), 1.0, 1, 1.0, 1, 1.0); }

// The bar held at x = L. Every DE and node is to keep
// m a0 unbalanced along x: the bar hangs under its own weight with g = -a0, so the stress is
// rho a0 x from the free end x = 0 and u(0) = -rho a0 L^2 / (2 E) (d sigma / dx = rho a0,
// sigma(0) = 0, u(L) = 0).
TEST(CouplingRelaxation, ABarRelaxesToItsOwnWeightsEquilibriumAndKeepsItsMotion) {
  constexpr double a0 = 1e-5, v0 = 0.01;
  const auto bar = coupled_bar(bar_mesh("relax_bar"), true);
  auto& cont = bar->cont;
  dem::DemModel& dem = bar->dem;
  CoupledModel& model = *bar->model;
  const double dt = 0.9 * model.critical_time_step();
  // A motion on the constraint (the same in both models where they overlap) that the relaxation
  // must give back: every free dof at v0 along x.
  for (auto& v : dem.particles.velocity) v = {v0, 0.0, 0.0};
  auto& vc = cont->velocity();
  for (std::size_t d = 0; d < vc.size(); d += 3)
    if (!cont->is_fixed(static_cast<int>(d))) vc[d] = v0;
  for (int n = 0; n < 4; ++n) model.step(dt);  // a state with a history: time, work, multipliers
  const std::vector<Vec3> dem_velocity = dem.particles.velocity;
  const std::vector<double> continuum_velocity = vc;
  const CoupledEnergies before = model.energies();
  const double time = model.time();

  StateArchive target;
  model.save_accelerations(target);
  const std::size_t n_dem = dem.particles.size(), n_dof = vc.size();
  target.put("accelerations/dem/translation", std::vector<Vec3>(n_dem, Vec3{a0, 0.0, 0.0}));
  target.put("accelerations/dem/rotation", std::vector<Vec3>(n_dem, Vec3{}));
  std::vector<double> nodes(n_dof, 0.0);
  for (std::size_t d = 0; d < n_dof; d += 3) nodes[d] = a0;
  target.put("accelerations/continuum", nodes);
  const CoupledModel::Relaxation r = model.relax(dt, 60000, target);

  // Converged: measured 1.7e-10 of the imbalance it started from (sum m |a - a0|^2; kinetic
  // damping converges slowly on the bar's longest mode).
  EXPECT_LT(r.imbalance_after, 1e-9 * r.imbalance_before);
  // Equilibrium of the whole: the held end carries the weight of every free dof (the multiplier
  // forces cancel over a rigid translation, which meets the constraint).
  double weight = 0.0, reaction = 0.0;
  for (std::size_t i = 0; i < n_dem; ++i) weight += a0 * dem.particles.mass(i);
  for (std::size_t d = 0; d < n_dof; d += 3)
    if (cont->is_fixed(static_cast<int>(d))) reaction += cont->force()[d];
    else weight += a0 * cont->dof_mass()[d];
  EXPECT_NEAR(-reaction, weight, 2e-5 * weight);  // measured 4.0e-6, what the imbalance leaves
  // The free end against the hanging bar's closed form (the weighted masses of the overlap and
  // the lumped ends differ from rho A dx by O(a / L)): measured +1.34 %.
  double tip = 0.0;
  int ends = 0;
  for (std::size_t i = 0; i < n_dem; ++i)
    if (dem.particles.reference[i].x == 0.0) tip += dem.particles.position[i].x - dem.particles.reference[i].x, ++ends;
  tip /= ends;
  const double closed_form = -a0 * L * L / 2.0;
  EXPECT_NEAR(tip, closed_form, 0.02 * std::abs(closed_form));
  // The relaxation moved displacements only, on the constraint.
  EXPECT_LT(model.displacement_residual(), 1e-10);  // measured 8.8e-12
  // The motion it found, put back onto G v = 0 by the resumption's projection (round-off).
  double changed = 0.0;
  for (std::size_t i = 0; i < n_dem; ++i) changed = std::max(changed, norm(dem.particles.velocity[i] - dem_velocity[i]));
  for (std::size_t d = 0; d < n_dof; ++d) changed = std::max(changed, std::abs(vc[d] - continuum_velocity[d]));
  EXPECT_LT(changed, 1e-12 * v0);
  EXPECT_EQ(model.time(), time);
  const CoupledEnergies after = model.energies();
  EXPECT_EQ(after.coupling_work, before.coupling_work);
  EXPECT_EQ(after.dem.external_work, before.dem.external_work);
  EXPECT_EQ(after.dem.dissipated, before.dem.dissipated);
  std::printf("[relax bar] imbalance %.3e -> %.3e, reaction %.6e of weight %.6e, tip %.6e (closed form %.6e, %+.3f %%), G u %.1e, "
              "velocities changed by %.1e\n",
              r.imbalance_before, r.imbalance_after, -reaction, weight, tip, closed_form, 100.0 * (tip / closed_form - 1.0),
              model.displacement_residual(), changed);

  // Relaxed toward its own accelerations, a state stays where it is.
  StateArchive own;
  model.save_accelerations(own);
  const std::vector<Vec3> relaxed = dem.particles.position;
  const CoupledModel::Relaxation again = model.relax(dt, 200, own);
  double moved = 0.0;
  for (std::size_t i = 0; i < n_dem; ++i) moved = std::max(moved, norm(dem.particles.position[i] - relaxed[i]));
  EXPECT_LT(moved, 1e-9 * std::abs(closed_form));
  EXPECT_LT(again.imbalance_before, 1e-20 * r.imbalance_before);
  std::printf("[relax bar] toward its own accelerations: imbalance %.3e, moved %.3e\n", again.imbalance_before, moved);
}

// The same bar, held nowhere, pulled along x on its pure-DEM part only (target a0 for the DEs at
// x < X1, 0 elsewhere). That target has a net force, which no static state balances: relax
// takes out its share on the free rigid motions (all six here), the uniform acceleration
// c = a0 m_pulled / m, and the bar relaxes to the stress of a free bar so driven: sigma(x) =
// (a0 - c) x on [0, X1], then falling by c per unit length to 0 at x = L. Its centre of mass
// stays where it was.
TEST(CouplingRelaxation, AFreeBarsNetForceIsLeftToTheRun) {
  constexpr double a0 = 1e-5;
  const auto bar = coupled_bar(bar_mesh("relax_free_bar"), false);
  auto& cont = bar->cont;
  dem::DemModel& dem = bar->dem;
  CoupledModel& model = *bar->model;
  const double dt = 0.9 * model.critical_time_step();
  const std::size_t n_dem = dem.particles.size(), n_dof = cont->velocity().size();
  double pulled = 0.0, mass = 0.0, moment_before = 0.0;
  std::vector<Vec3> translation(n_dem, Vec3{});
  for (std::size_t i = 0; i < n_dem; ++i) {
    const double m = dem.particles.mass(i);
    if (dem.particles.reference[i].x < X1) translation[i] = {a0, 0.0, 0.0}, pulled += m;
    mass += m, moment_before += m * dem.particles.position[i].x;
  }
  for (std::size_t d = 0; d < n_dof; d += 3) mass += cont->dof_mass()[d], moment_before += cont->dof_mass()[d] * cont->nodes()[d / 3].x;
  StateArchive target;
  target.put("accelerations/dem/translation", translation);
  target.put("accelerations/dem/rotation", std::vector<Vec3>(n_dem, Vec3{}));
  target.put("accelerations/continuum", std::vector<double>(n_dof, 0.0));
  const CoupledModel::Relaxation r = model.relax(dt, 60000, target);

  EXPECT_EQ(r.free_rigid_motions, 6);
  EXPECT_LT(r.imbalance_after, 1e-12 * r.imbalance_before);  // measured 1.0e-15
  double moment_after = 0.0;
  for (std::size_t i = 0; i < n_dem; ++i) moment_after += dem.particles.mass(i) * dem.particles.position[i].x;
  for (std::size_t d = 0; d < n_dof; d += 3) moment_after += cont->dof_mass()[d] * (cont->nodes()[d / 3].x + cont->displacement()[d]);
  // The elongation u(L) - u(0) = int sigma / E dx against the free bar's closed form.
  const double c = a0 * pulled / mass;
  const double closed_form = (a0 - c) * X1 * X1 / 2.0 + (a0 - c) * X1 * (L - X1) - c * (L - X1) * (L - X1) / 2.0;
  double u0 = 0.0, uL = 0.0;
  int ends = 0, far = 0;
  for (std::size_t i = 0; i < n_dem; ++i)
    if (dem.particles.reference[i].x == 0.0) u0 += dem.particles.position[i].x - dem.particles.reference[i].x, ++ends;
  for (std::size_t d = 0; d < n_dof; d += 3)
    if (cont->nodes()[d / 3].x == L) uL += cont->displacement()[d], ++far;
  const double elongation = uL / far - u0 / ends;
  EXPECT_NEAR(elongation, closed_form, 0.005 * std::abs(closed_form));  // measured -0.094 %
  // The centre of mass stays: measured 6e-9 of the elongation.
  EXPECT_LT(std::abs(moment_after - moment_before) / mass, 1e-7 * std::abs(closed_form));
  std::printf("[relax free bar] %d free rigid motions, imbalance %.3e -> %.3e, elongation %.6e (closed form %.6e, %+.3f %%), "
              "centre of mass moved %.2e\n",
              r.free_rigid_motions, r.imbalance_before, r.imbalance_after, elongation, closed_form, 100.0 * (elongation / closed_form - 1.0),
              (moment_after - moment_before) / mass);
}

// A state set from outside opens a macro step of the model it is set into: with
// continuum_substeps: auto a following band's moved scene may take another number of substeps
// than the scene its state came from, at a step count that is no multiple of it. The hanging
// bar's model with the continuum's force every second step, four steps into a motion, its state
// set into the same bar with every third (step count 4): that model's next steps are, to the
// bit, those of the same state set with the step count 0, where the macro steps begin anyway.
TEST(CouplingRelaxation, AStateSetFromOutsideOpensAMacroStep) {
  constexpr double v0 = 0.01;
  const std::string mesh = bar_mesh("relax_macro_step");
  // A motion with strain: velocities growing along the bar, then four steps at m = 2.
  const auto first = coupled_bar(mesh, true, 2);
  for (std::size_t i = 0; i < first->dem.particles.size(); ++i) first->dem.particles.velocity[i] = {v0 * first->dem.particles.reference[i].x / L, 0.0, 0.0};
  auto& vc = first->cont->velocity();
  for (std::size_t d = 0; d < vc.size(); d += 3)
    if (!first->cont->is_fixed(static_cast<int>(d))) vc[d] = v0 * first->cont->nodes()[d / 3].x / L;
  const auto third = coupled_bar(mesh, true, 3), from_zero = coupled_bar(mesh, true, 3);
  const double dt = 0.9 * std::min(first->model->critical_time_step(), third->model->critical_time_step());
  for (int n = 0; n < 4; ++n) first->model->step(dt);
  StateArchive state;
  first->model->save_state(state);
  third->model->load_state(state);
  third->model->resume_from_set_state();
  state.put("coupling/steps", std::int64_t{0});
  from_zero->model->load_state(state);
  from_zero->model->resume_from_set_state();
  EXPECT_TRUE(third->model->opens_macro_step());
  for (int n = 0; n < 7; ++n) third->model->step(dt), from_zero->model->step(dt);
  for (std::size_t i = 0; i < third->dem.particles.size(); ++i) {
    EXPECT_EQ(third->dem.particles.position[i].x, from_zero->dem.particles.position[i].x) << "DE " << i;
    EXPECT_EQ(third->dem.particles.velocity[i].x, from_zero->dem.particles.velocity[i].x) << "DE " << i;
  }
  for (std::size_t d = 0; d < vc.size(); ++d) {
    EXPECT_EQ(third->cont->displacement()[d], from_zero->cont->displacement()[d]) << "dof " << d;
    EXPECT_EQ(third->cont->velocity()[d], from_zero->cont->velocity()[d]) << "dof " << d;
  }
  EXPECT_EQ(third->model->energies().total(), from_zero->model->energies().total());
  EXPECT_FALSE(third->model->opens_macro_step());  // seven steps: one into the third macro step
}

}  // namespace
