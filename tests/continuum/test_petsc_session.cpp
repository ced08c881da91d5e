// SPDX-License-Identifier: GPL-3.0-or-later
// PetscSession's MPI session directory (docs/decisions.md#d58): a singleton's Open MPI files go to
// a directory of this process's own, which is gone once the process has exited.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "continuum/petsc_session.hpp"

namespace fs = std::filesystem;
using arlequin::continuum::PetscSession;

namespace {
// Read before any test runs: a base the environment already gives is kept, and then there is
// nothing of ours to check.
const bool g_base_given = std::getenv("OMPI_MCA_orte_tmpdir_base") != nullptr;

// In the child: start PETSc, report the base through `fd`, exit 0 if Open MPI's files are in it.
[[noreturn]] void start_petsc_and_report(int fd) {
  PetscSession::ensure();
  const char* base = std::getenv("OMPI_MCA_orte_tmpdir_base");
  const std::string path = base ? base : "";
  if (write(fd, path.data(), path.size()) != static_cast<ssize_t>(path.size())) std::_Exit(3);
  close(fd);
  bool has_mpi_files = false;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(path, error))
    has_mpi_files = has_mpi_files || entry.path().filename().string().rfind("ompi.", 0) == 0;
  std::exit(has_mpi_files ? 0 : 2);  // exit(), not _Exit: PetscFinalize runs in the static's destructor
}
}  // namespace

TEST(ContinuumPetscSession, MpiKeepsItsFilesInADirectoryOfItsOwn) {
  if (g_base_given) GTEST_SKIP() << "OMPI_MCA_orte_tmpdir_base is set in the environment";
  ASSERT_FALSE(PetscSession::started());  // MPI is started in the child only
  int pipe_fds[2];
  ASSERT_EQ(pipe(pipe_fds), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    close(pipe_fds[0]);
    start_petsc_and_report(pipe_fds[1]);
  }
  close(pipe_fds[1]);
  std::string base;
  char buffer[4096];
  for (ssize_t n; (n = read(pipe_fds[0], buffer, sizeof buffer)) > 0;) base.append(buffer, n);
  close(pipe_fds[0]);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  const char* tmp = std::getenv("TMPDIR");
  const std::string expected_prefix = std::string(tmp && *tmp ? tmp : "/tmp") + "/arlequin-mpi-";
  EXPECT_EQ(base.rfind(expected_prefix, 0), 0u) << "the base MPI was given: '" << base << "'";
  EXPECT_EQ(WEXITSTATUS(status), 0) << "no ompi.* directory of Open MPI's in " << base;
  EXPECT_FALSE(fs::exists(base)) << base << " is left after the process's exit";
}
