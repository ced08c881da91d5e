// SPDX-License-Identifier: GPL-3.0-or-later
// PetscSession: PETSc is started on the first call that needs it and finalised at program exit.
// Contract: `ensure(options)` may be called any number of times from the thread that builds
// continua; the first call runs PetscInitialize (MPI included) with `options` (a PETSc option
// string such as "-ksp_type cg -pc_type gamg", usually the case file's plus the command line's);
// later calls add nothing. Pure-DEM programs never call it, so they never start PETSc or MPI.
#pragma once
#include <string>

struct _n_PetscOptions;  // PETSc's PetscOptions is a pointer to it (petscoptions.h)

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

// The options of one PETSc solver, in a database of their own that is in force (pushed over
// the global one) while this object lives: one solver's options never reach another's, nor do
// the command line's reach it. Construct before the solver's SetFromOptions / SetUp calls.
class ScopedPetscOptions {
 public:
  explicit ScopedPetscOptions(const std::string& options);  // RunError if PETSc cannot parse them
  ~ScopedPetscOptions();
  ScopedPetscOptions(const ScopedPetscOptions&) = delete;
  ScopedPetscOptions& operator=(const ScopedPetscOptions&) = delete;
  // The options nothing has read so far ("-name value" pairs, space-separated; "" if none).
  std::string unused() const;

 private:
  ::_n_PetscOptions* db_ = nullptr;
};

}  // namespace arlequin::continuum
