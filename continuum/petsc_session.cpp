#include "continuum/petsc_session.hpp"

#include <petscsys.h>

#include "common/error.hpp"

namespace arlequin::continuum {

namespace {
bool g_started = false;
}

PetscSession::PetscSession(const std::string& options) {
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

}  // namespace arlequin::continuum
