// SPDX-License-Identifier: GPL-3.0-or-later
// Sample files: a packed sample's DEs and how it was built, in HDF5, so that a long packing
// is built once and the runs that use it start from identical DEs.
//
// Layout (format attribute "arlequin sample", version 1 on the root group):
//   /particles/position   n x 3 double, m
//   /particles/radius     n double, m
//   /particles/groups     n uint32, group bit masks
//   /packing              group whose attributes hold the PackingSpec (region as a shape name
//                         plus its numbers, seed, ...) and the PackingReport (count,
//                         compaction, coordination, fabric eigenvalues, radius histogram, ...)
// Contract: save_sample writes "<path>.tmp" and renames it over path (readers never see a
// partial file), creating missing directories; failures are RunError naming the file.
// load_sample appends the DEs to p at rest with identity orientation, masses from `density`,
// and returns what was saved bit for bit; a missing file, a file that is not HDF5 or not a
// sample, or missing/misshapen data is an InputError naming the file (and the item).
#pragma once
#include <filesystem>

#include "dem/packing.hpp"

namespace arlequin::dem {

struct SampleRecord {
  PackingSpec spec;
  PackingReport report;
};

void save_sample(const std::filesystem::path& path, const ParticleSet& p, const PackingSpec& spec,
                 const PackingReport& report);

SampleRecord load_sample(const std::filesystem::path& path, ParticleSet& p, double density);

}  // namespace arlequin::dem
