// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/registry.hpp"

#include "common/error.hpp"
#include "continuum/fe/fe_solver.hpp"
#include "continuum/nem/nem_solver.hpp"

namespace arlequin::continuum {

namespace {
const SolverEntry kSolvers[] = {
    {"fe", &FeSolver::create, "Lagrange tetrahedra (P1 or P2 from the mesh order), lumped mass"},
    {"nem", &NemSolver::create, "natural neighbour (Sibson/Laplace) with stabilised conforming nodal integration"},
};
}  // namespace

std::span<const SolverEntry> continuum_solvers() { return kSolvers; }

std::unique_ptr<ContinuumSolver> make_continuum_solver(const std::string& name, const ContinuumSettings& settings) {
  std::string known;
  for (const SolverEntry& e : kSolvers) {
    if (name == e.name) return e.make(settings);
    known += (known.empty() ? "" : ", ") + std::string(e.name);
  }
  throw InputError("unknown continuum solver '" + name + "' (known: " + known + ")");
}

}  // namespace arlequin::continuum
