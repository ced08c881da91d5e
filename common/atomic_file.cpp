// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/atomic_file.hpp"

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

}  // namespace

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
