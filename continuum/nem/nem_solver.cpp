#include "continuum/nem/nem_solver.hpp"

#include "common/error.hpp"

namespace arlequin::continuum {
struct NemSolver::Geometry {};
std::unique_ptr<ContinuumSolver> NemSolver::create(const ContinuumSettings& settings) {
  return std::make_unique<NemSolver>(settings);
}
NemSolver::NemSolver(const ContinuumSettings& settings) : ContinuumSolver(settings) { throw InputError("nem: TODO"); }
NemSolver::~NemSolver() = default;
InterpolationOperator NemSolver::interpolation(const std::vector<Vec3>&) const { return {}; }
std::vector<double> NemSolver::weighted_lumped_mass(const ScalarFunction&) const { return {}; }
}  // namespace arlequin::continuum
