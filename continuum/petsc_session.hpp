// PetscSession: PETSc is started on the first call that needs it and finalised at program exit.
// Contract: `ensure(options)` may be called any number of times from the thread that builds
// continua; the first call runs PetscInitialize (MPI included) with `options` (a PETSc option
// string such as "-ksp_type cg -pc_type gamg", usually the case file's plus the command line's);
// later calls add nothing. Pure-DEM programs never call it, so they never start PETSc or MPI.
#pragma once
#include <string>

namespace arlequin::continuum {

class PetscSession {
 public:
  static void ensure(const std::string& options = "");
  static bool started();

 private:
  PetscSession(const std::string& options);
  ~PetscSession();  // PetscFinalize, when the static instance dies at exit
};

// Throws RunError naming `what` when a PETSc call returned an error code.
void petsc_check(int code, const char* what);

}  // namespace arlequin::continuum
