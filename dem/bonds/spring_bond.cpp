// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/bonds/spring_bond.hpp"

#include <cmath>

#include "common/case_file.hpp"

namespace arlequin::dem {

template class BondKernelSet<SpringBondSet>;

constexpr KeyDoc spring_keys[] = {
    {"stiffness", KeyType::number, "N/m", Range::positive(), "(or axial_rigidity)", "axial stiffness K of one spring (seed Eq. 6, Eq. 8 for a yarn)"},
    {"axial_rigidity", KeyType::number, "N", Range::positive(), "(or stiffness)", "EA instead of K: each spring K = EA / L0, its own rest length"},
    {"max_elongation", KeyType::number, "1", Range::non_negative(), "0", "elongation (L - L0) / L0 at which it breaks; 0: never"},
};
std::span<const KeyDoc> SpringBondSet::keys() { return spring_keys; }

std::unique_ptr<BondSet> SpringBondSet::make(CaseNode& section) {
  if (section.has("axial_rigidity")) {
    if (section.has("stiffness")) section.fail("stiffness", "give either stiffness or axial_rigidity, not both");
    const double EA = section.number("axial_rigidity", Range::positive(), "N");
    return with_axial_rigidity(EA, section.number_or("max_elongation", 0.0, Range::non_negative(), "1"));
  }
  const double stiffness = section.number("stiffness", Range::positive(), "N/m");
  return std::make_unique<SpringBondSet>(stiffness, section.number_or("max_elongation", 0.0, Range::non_negative(), "1"));
}

void SpringBondSet::add(std::uint32_t i, std::uint32_t j, const ParticleSet& p) {
  add_pair(i, j);
  const double L0 = norm(p.position[j] - p.position[i]);
  rest_length_.push_back(L0);
  stiffness_.push_back(axial_rigidity_ > 0.0 ? axial_rigidity_ / L0 : nominal_stiffness_);
}

void SpringBondSet::reorder(std::span<const std::uint32_t> order) {
  apply_order(rest_length_, order);
  apply_order(stiffness_, order);
}

// One translational row per end: K (1/m_i + 1/sqrt(m_i m_j)).
void SpringBondSet::add_frequency_bound(std::size_t b, const ParticleSet& p, std::span<double> translational,
                                        std::span<double>) const {
  const double mi = p.inv_mass[first_[b]], mj = p.inv_mass[second_[b]];
  translational[first_[b]] += stiffness_[b] * (mi + std::sqrt(mi * mj));
  translational[second_[b]] += stiffness_[b] * (mj + std::sqrt(mi * mj));
}

}  // namespace arlequin::dem
