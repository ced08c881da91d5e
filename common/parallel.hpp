// Shared by the OpenMP loops of the DEM and the continuum (built with ARLEQUIN_WITH_OPENMP;
// without it the pragmas are ignored and every loop runs on one thread).
#pragma once

namespace arlequin {

// Loops of at most this many items run on one thread: below it, starting threads costs more
// than it saves.
inline constexpr long parallel_threshold = 4096;
// The same for loops over bonds (one colour of a bond set), whose items cost 10-100 times a
// DE's update: a random packing's bond sets colour into ~20 colours of a few hundred to a few
// thousand bonds, which parallel_threshold kept on one thread (the 10k REV: 3.3 ms per step on
// 2 threads against 1.8 ms with this one, 2026-11-25).
inline constexpr long parallel_threshold_bonds = 512;

}  // namespace arlequin
