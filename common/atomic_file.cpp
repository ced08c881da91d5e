// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/atomic_file.hpp"

#include <signal.h>
#include <unistd.h>

#include <fstream>
#include <iterator>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>

#include "common/error.hpp"

namespace arlequin {

namespace {

[[noreturn]] void fail(const std::filesystem::path& path, std::string_view what, const std::string& why) {
  throw RunError("cannot " + std::string(what) + " '" + path.string() + "': " + why);
}

// The pid at the end of "<name>.tmp.<pid>" or "<name>.part.<pid>"; 0 if the name is not one.
pid_t writer_pid(const std::string& name) {
  for (const char* marker : {".tmp.", ".part."}) {
    const std::size_t at = name.rfind(marker);
    if (at == std::string::npos || at == 0) continue;
    const std::string digits = name.substr(at + std::strlen(marker));
    if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    return static_cast<pid_t>(std::stol(digits));
  }
  return 0;
}

// Whether process `pid` still runs: kill(pid, 0) probes it (ESRCH: none; EPERM: alive, another
// user's), and a zombie (killed, not yet reaped; state Z in /proc/<pid>/stat) counts as gone.
bool process_running(pid_t pid) {
  if (::kill(pid, 0) != 0 && errno == ESRCH) return false;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return true;
  const std::size_t name_end = line.rfind(')');  // the command name is in parentheses and may hold spaces
  return name_end == std::string::npos || name_end + 2 >= line.size() || line[name_end + 2] != 'Z';
}

}  // namespace

std::size_t remove_stale_temporaries(const std::filesystem::path& dir) {
  std::size_t removed = 0;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const pid_t pid = writer_pid(entry.path().filename().string());
    if (pid <= 0 || !entry.is_regular_file() || process_running(pid)) continue;
    if (std::filesystem::remove(entry.path(), ec)) ++removed;
  }
  return removed;
}

std::filesystem::path temporary_path_for(const std::filesystem::path& path) {
  // The process id keeps writers apart (e.g. MPI ranks writing the same result file): each
  // renames its own complete copy into place.
  std::filesystem::path tmp = path;
  tmp += ".tmp." + std::to_string(::getpid());
  return tmp;
}

void write_file_atomically(const std::filesystem::path& path, std::string_view content) {
  std::error_code ec;
  if (path.has_parent_path()) {
    std::filesystem::create_directories(path.parent_path(), ec);
    if (ec) fail(path.parent_path(), "create directory", ec.message());
  }
  const std::filesystem::path tmp = temporary_path_for(path);
  std::FILE* file = std::fopen(tmp.c_str(), "wb");
  if (file == nullptr) fail(tmp, "open", std::strerror(errno));
  // No fsync: the point is that concurrent readers and a crashed run never see a torn
  // file; surviving a power cut is not worth a disk sync on every periodic rewrite.
  const bool written = std::fwrite(content.data(), 1, content.size(), file) == content.size() &&
                       std::fflush(file) == 0;
  const int write_errno = errno;
  if (std::fclose(file) != 0 || !written) {
    const int code = written ? errno : write_errno;
    std::filesystem::remove(tmp, ec);  // best effort: do not leave the partial file around
    fail(tmp, "write", std::strerror(code));
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    const std::string why = ec.message();
    std::filesystem::remove(tmp, ec);
    fail(path, "replace", why);
  }
}

std::string read_text_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot read file");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace arlequin
