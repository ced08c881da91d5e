// SPDX-License-Identifier: GPL-3.0-or-later
// PetscSession's MPI session directory (docs/decisions.md#d58): a singleton's Open MPI files go to
// a directory of this process's own, which is gone once the process has exited.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "continuum/petsc_session.hpp"
#include "support/cli.hpp"

namespace fs = std::filesystem;
using arlequin::continuum::PetscSession;

namespace {
// Read before any test runs: a base the environment already gives is kept, and then there is
// nothing of ours to check.
const bool g_base_given = std::getenv("OMPI_MCA_orte_tmpdir_base") != nullptr;

// The arlequin-mpi-* folders in `dir` and whether each holds Open MPI's ompi.* directory.
std::vector<std::pair<std::string, bool>> session_bases(const fs::path& dir) {
  std::vector<std::pair<std::string, bool>> found;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(dir, error)) {
    if (entry.path().filename().string().rfind("arlequin-mpi-", 0) != 0) continue;
    bool has_mpi_files = false;
    for (const auto& inside : fs::directory_iterator(entry.path(), error))
      has_mpi_files = has_mpi_files || inside.path().filename().string().rfind("ompi.", 0) == 0;
    found.emplace_back(entry.path().string(), has_mpi_files);
  }
  return found;
}
}  // namespace

// In a child process with a TMPDIR of its own: once PETSc (hence MPI) has started, TMPDIR holds
// one arlequin-mpi-* folder with Open MPI's files, and the environment no longer names it (a
// program the child starts makes its own); once the child has exited, the folder is gone.
TEST(ContinuumPetscSession, MpiKeepsItsFilesInADirectoryOfItsOwn) {
  if (g_base_given) GTEST_SKIP() << "OMPI_MCA_orte_tmpdir_base is set in the environment";
  ASSERT_FALSE(PetscSession::started());  // MPI is started in the child only
  const fs::path tmp = arlequin::test::scratch_dir("petsc_session_" + std::to_string(getpid()));
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    setenv("TMPDIR", tmp.c_str(), 1);
    PetscSession::ensure();
    const auto bases = session_bases(tmp);
    const bool ok = bases.size() == 1 && bases[0].second && !std::getenv("OMPI_MCA_orte_tmpdir_base");
    std::exit(ok ? 0 : 2);  // exit(), not _Exit: PetscFinalize runs in the static's destructor
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "while MPI ran, TMPDIR did not hold one arlequin-mpi-* folder with Open MPI's "
                                       "files, or the environment still named it";
  const auto left = session_bases(tmp);
  EXPECT_TRUE(left.empty()) << left.front().first << " is left after the process's exit";
  fs::remove_all(tmp);
}
