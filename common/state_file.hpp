// SPDX-License-Identifier: GPL-3.0-or-later
// A StateArchive in one HDF5 file (the run's checkpoint, app/checkpoint.hpp).
//
// Layout: one dataset per entry at its name ("dem/particles/velocity": rows x width, or rows
// when width is 1; float64, int64, uint32 or uint8; a text as uint8 bytes), and /index, the
// text "name<TAB>kind<TAB>width<TAB>rows" per line, in name order. The root attribute
// `checksum` is FNV-1a (64 bit) over the index and every entry's bytes in that order, so a
// file whose bytes changed after it was written is refused even where HDF5 reads it.
// The file is written under a temporary name and renamed: a reader never sees it half done.
#pragma once
#include <filesystem>

#include "common/state_archive.hpp"

namespace arlequin {

// Throws RunError naming the file when it cannot be written.
void write_state_file(const std::filesystem::path& path, const StateArchive& archive);
// Throws InputError naming the file: missing, not HDF5 or truncated, no index (not a state
// file), or corrupted (an entry unreadable or the checksum differs).
StateArchive read_state_file(const std::filesystem::path& path);

}  // namespace arlequin
