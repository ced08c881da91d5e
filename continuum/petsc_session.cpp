// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/petsc_session.hpp"

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include <petscsys.h>

#include "common/error.hpp"

namespace arlequin::continuum {

namespace {
bool g_started = false;

// Open MPI's session base made for this process (empty where one was set already or none could
// be made), removed at exit.
std::string g_mpi_session_base;

// Open MPI 4 starts a singleton in <base>/ompi.<host>.<uid>, a directory every process on the
// host shares and the last one to finalise removes: two processes that start or finish in the
// same instant race on it, and one fails in MPI_Init ("mkdir ... File exists"; parallel ctest
// and case sweeps do this). A base of this process's own takes it out of the race
// (docs/decisions.md#d58). A base already set is kept: the user's, or mpirun's for the processes
// it launches, which must find its session directory.
void give_mpi_a_session_base_of_its_own() {
  if (std::getenv("OMPI_MCA_orte_tmpdir_base")) return;
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/arlequin-mpi-XXXXXX";
  if (!mkdtemp(pattern.data())) return;  // MPI then uses its shared default, as without us
  g_mpi_session_base = pattern;
  setenv("OMPI_MCA_orte_tmpdir_base", g_mpi_session_base.c_str(), /*overwrite=*/1);
}

void remove_mpi_session_base() {
  if (g_mpi_session_base.empty()) return;
  std::error_code ignored;  // nothing to do at exit if it cannot be removed
  std::filesystem::remove_all(g_mpi_session_base, ignored);
  g_mpi_session_base.clear();
}
}  // namespace

PetscSession::PetscSession(const std::string& options) {
  // MPI_Init runs hwloc's topology discovery, which prints three lines to stderr where /sys is
  // not mounted (containers, chroots) and discovers nothing we use: a one-line error of ours
  // would come with them. Its messages are hidden unless the user set HWLOC_HIDE_ERRORS.
  setenv("HWLOC_HIDE_ERRORS", "2", /*overwrite=*/0);
  give_mpi_a_session_base_of_its_own();
  // No argc/argv: options reach PETSc through the string only, so the application decides
  // which command-line words are PETSc's.
  const PetscErrorCode code = PetscInitialize(nullptr, nullptr, nullptr, nullptr);
  // MPI has read it: the environment goes back to what it was, so that a program this one starts
  // (a test running a case) makes a base of its own instead of sharing this one.
  if (!g_mpi_session_base.empty()) unsetenv("OMPI_MCA_orte_tmpdir_base");
  if (code != 0) {
    remove_mpi_session_base();
    petsc_check(code, "PetscInitialize");
  }
  if (!options.empty()) petsc_check(PetscOptionsInsertString(nullptr, options.c_str()), "PETSc options");
  g_started = true;
}

PetscSession::~PetscSession() {
  PetscFinalize();
  remove_mpi_session_base();
  g_started = false;
}

void PetscSession::ensure(const std::string& options) {
  static PetscSession session(options);  // function-local static: initialised once, destroyed at exit
}

bool PetscSession::started() { return g_started; }

void petsc_check(int code, const char* what) {
  if (code != 0) throw RunError(std::string("PETSc failed in ") + what + " (error code " + std::to_string(code) + ")");
}

ScopedPetscOptions::ScopedPetscOptions(const std::string& options) {
  petsc_check(PetscOptionsCreate(&db_), "PetscOptionsCreate");
  if (const PetscErrorCode code = PetscOptionsInsertString(db_, options.c_str()); code != 0) {
    PetscOptionsDestroy(&db_);
    petsc_check(code, "PETSc options");
  }
  if (const PetscErrorCode code = PetscOptionsPush(db_); code != 0) {
    PetscOptionsDestroy(&db_);
    petsc_check(code, "PetscOptionsPush");
  }
}

ScopedPetscOptions::~ScopedPetscOptions() {
  PetscOptionsPop();
  PetscOptionsDestroy(&db_);
}

std::string ScopedPetscOptions::unused() const {
  PetscInt n = 0;
  char **names = nullptr, **values = nullptr;
  petsc_check(PetscOptionsLeftGet(db_, &n, &names, &values), "PetscOptionsLeftGet");
  std::string list;
  for (PetscInt i = 0; i < n; ++i) {
    if (!list.empty()) list += ' ';
    list += std::string("-") + names[i];
    if (values[i]) list += std::string(" ") + values[i];
  }
  petsc_check(PetscOptionsLeftRestore(db_, &n, &names, &values), "PetscOptionsLeftRestore");
  return list;
}

}  // namespace arlequin::continuum
