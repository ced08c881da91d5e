// Shared by the OpenMP loops of the DEM and the continuum (built with ARLEQUIN_WITH_OPENMP;
// without it the pragmas are ignored and every loop runs on one thread).
#pragma once

namespace arlequin {

// Loops shorter than this run on one thread: below it, starting threads costs more than it saves.
inline constexpr long parallel_threshold = 4096;

}  // namespace arlequin
