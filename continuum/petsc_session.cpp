// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/petsc_session.hpp"

#include <cstdlib>

#include <petscsys.h>

#include "common/error.hpp"

namespace arlequin::continuum {

namespace {
bool g_started = false;
}

PetscSession::PetscSession(const std::string& options) {
  // MPI_Init runs hwloc's topology discovery, which prints three lines to stderr where /sys is
  // not mounted (containers, chroots) and discovers nothing we use: a one-line error of ours
  // would come with them. Its messages are hidden unless the user set HWLOC_HIDE_ERRORS.
  setenv("HWLOC_HIDE_ERRORS", "2", /*overwrite=*/0);
  // No argc/argv: options reach PETSc through the string only, so the application decides
  // which command-line words are PETSc's.
  petsc_check(PetscInitialize(nullptr, nullptr, nullptr, nullptr), "PetscInitialize");
  if (!options.empty()) petsc_check(PetscOptionsInsertString(nullptr, options.c_str()), "PETSc options");
  g_started = true;
}

PetscSession::~PetscSession() {
  PetscFinalize();
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
