// SPDX-License-Identifier: GPL-3.0-or-later
// continuum_mpi_check: the distributed static solve against a serial one, for CTest's
// ContinuumMpi.MatchesSerial (run under `mpiexec -n 2`; any number of ranks works, one too).
//
// Case: P1 cantilever (meshes/cantilever.geo, size 0.25), clamped at x = 0, shear traction on
// the tip. Serial answer, on every rank: K assembled column by column from internal_force
// (K e_j, no PETSc), f from compute_forces at u = 0, the free block solved by Eigen's sparse
// Cholesky. Distributed answer: solve_static with MUMPS LU on PETSC_COMM_WORLD, gathered to
// every rank. Both are direct solves, so they must agree to round-off: the check is
// max |u_mpi - u_serial| <= 1e-10 max |u_serial| on every rank (exit code 1 otherwise).
#include <mpi.h>

#include <Eigen/SparseCholesky>
#include <cmath>
#include <cstdio>

#include "continuum/registry.hpp"

using namespace arlequin;
using namespace arlequin::continuum;

int main() {
  ContinuumSettings settings;
  settings.mesh = {std::string(ARLEQUIN_SOURCE_DIR) + "/meshes/cantilever.geo", 0.25, 1, {}};
  settings.materials = {{"", Material::isotropic(1000.0, 0.3, 1.0)}};
  auto s = make_continuum_solver("fe", settings);  // starts PETSc, hence MPI
  int rank, size;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  s->fix("clamp", {true, true, true}, [](const Vec3&, double) { return Vec3{}; });
  s->add_traction("tip", [](const Vec3&, double) { return Vec3{0, 0, 1e-2}; });

  // Serial reference on the free dofs.
  const int n = 3 * s->num_nodes();
  std::vector<int> free_index(n, 0);
  for (int node : s->mesh().group("clamp").nodes)
    for (int c = 0; c < 3; ++c) free_index[3 * node + c] = -1;
  int nf = 0;
  for (int& f : free_index)
    if (f == 0) f = nf++;
  s->compute_forces();  // u = 0: the force is f_ext
  Eigen::VectorXd f(nf);
  for (int d = 0; d < n; ++d)
    if (free_index[d] >= 0) f[free_index[d]] = s->force()[d];
  std::vector<Eigen::Triplet<double>> trip;
  Field e(n, 0.0), column;
  for (int j = 0; j < n; ++j) {
    if (free_index[j] < 0) continue;
    e[j] = 1.0;
    s->internal_force(e, column);
    e[j] = 0.0;
    for (int i = 0; i < n; ++i)
      if (free_index[i] >= 0 && column[i] != 0.0) trip.emplace_back(free_index[i], free_index[j], column[i]);
  }
  Eigen::SparseMatrix<double> K(nf, nf);
  K.setFromTriplets(trip.begin(), trip.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(K);
  const Eigen::VectorXd u_serial = ldlt.solve(f);

  s->solve_static("-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps");
  double diff = 0, scale = 0;
  for (int d = 0; d < n; ++d) {
    const double ref = free_index[d] >= 0 ? u_serial[free_index[d]] : 0.0;
    diff = std::max(diff, std::abs(s->displacement()[d] - ref));
    scale = std::max(scale, std::abs(ref));
  }
  const bool ok = ldlt.info() == Eigen::Success && diff <= 1e-10 * scale;
  std::printf("rank %d of %d: %d dofs, max |u_mpi - u_serial| / max |u_serial| = %.3e (max |u| %.6e): %s\n", rank,
              size, n, diff / scale, scale, ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
