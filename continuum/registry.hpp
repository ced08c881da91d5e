// SPDX-License-Identifier: GPL-3.0-or-later
// Registry of continuum discretisations, keyed by the name the case file uses.
// Adding a method = one .hpp/.cpp pair deriving from ContinuumSolver + one row in registry.cpp.
#pragma once
#include <memory>
#include <span>
#include <string>

#include "continuum/continuum_solver.hpp"

namespace arlequin::continuum {

struct SolverEntry {
  const char* name;
  std::unique_ptr<ContinuumSolver> (*make)(const ContinuumSettings&);
  const char* description;
};

std::span<const SolverEntry> continuum_solvers();
// InputError for an unknown name (the message lists the known ones).
std::unique_ptr<ContinuumSolver> make_continuum_solver(const std::string& name, const ContinuumSettings& settings);

}  // namespace arlequin::continuum
