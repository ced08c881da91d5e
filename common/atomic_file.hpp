// SPDX-License-Identifier: GPL-3.0-or-later
// Whole-file writes that readers never see half done: outputs are re-written while a run
// is going (CSV series, XDMF index, summaries) and may be opened by a viewer or a script
// at any moment, or left behind by a killed run.
#pragma once
#include <cstddef>
#include <filesystem>
#include <string_view>

namespace arlequin {

// The sibling file a new version of `path` is written to before it replaces `path`:
// `path` + ".tmp.<pid>". Same directory, so the final rename never crosses file systems.
std::filesystem::path temporary_path_for(const std::filesystem::path& path);

// Writes `content` to temporary_path_for(path), closes it, then renames it over `path`
// (atomic on POSIX: readers see the old or the new file, never a mix). Creates missing
// parent directories. Throws RunError naming the path and the system error.
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

// Removes from `dir` what a writer killed before its rename left behind (SIGKILL, a second
// Ctrl-C): files named <name>.tmp.<pid> (temporary_path_for) or <name>.part.<pid> (the fields
// writer's HDF5 file) whose process no longer runs. Returns how many it removed.
std::size_t remove_stale_temporaries(const std::filesystem::path& dir);

// The whole content of a text file; InputError naming the file if it cannot be read.
std::string read_text_file(const std::filesystem::path& path);

}  // namespace arlequin
