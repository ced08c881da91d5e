// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/bonds/spring_bond.hpp"

#include <cmath>

#include "common/case_file.hpp"

namespace arlequin::dem {

template class BondKernelSet<SpringBondSet>;

constexpr KeyDoc spring_keys[] = {
    {"stiffness", KeyType::number, "N/m", Range::positive(), "", "axial stiffness K of one spring (seed Eq. 6, Eq. 8 for a yarn)"},
    {"max_elongation", KeyType::number, "1", Range::non_negative(), "0", "elongation (L - L0) / L0 at which it breaks; 0: never"},
};
std::span<const KeyDoc> SpringBondSet::keys() { return spring_keys; }

std::unique_ptr<BondSet> SpringBondSet::make(CaseNode& section) {
  const double stiffness = section.number("stiffness", Range::positive(), "N/m");
  return std::make_unique<SpringBondSet>(stiffness, section.number_or("max_elongation", 0.0, Range::non_negative(), "1"));
}

void SpringBondSet::add(std::uint32_t i, std::uint32_t j, const ParticleSet& p) {
  add_pair(i, j);
  rest_length_.push_back(norm(p.position[j] - p.position[i]));
  stiffness_.push_back(nominal_stiffness_);
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
