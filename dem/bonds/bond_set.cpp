// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/bonds/bond_set.hpp"

#include <algorithm>
#include <bit>
#include <numeric>
#include <stdexcept>

namespace arlequin::dem {

std::vector<std::uint32_t> BondColouring::build(std::span<const std::uint32_t> first,
                                                std::span<const std::uint32_t> second,
                                                std::size_t n_particles) {
  const std::size_t n = first.size();
  // Greedy edge colouring: a bond takes the lowest colour free at both its DEs, so at most
  // 2 max_degree - 1 colours; each DE keeps a bitset of its taken colours in `words` 64-bit
  // words (one for any usual packing; a DE bonded to hundreds, a large DE among small ones,
  // takes more).
  std::vector<std::uint32_t> degree(n_particles, 0);
  for (std::size_t b = 0; b < n; ++b) ++degree[first[b]], ++degree[second[b]];
  const std::uint32_t max_degree = n_particles > 0 ? *std::max_element(degree.begin(), degree.end()) : 0;
  const std::size_t words = (2 * std::size_t(max_degree) + 63) / 64;
  std::vector<std::uint64_t> used(n_particles * words, 0);  // colours already taken at each DE
  std::vector<std::uint32_t> colour(n);
  std::uint32_t n_colours = 0;
  for (std::size_t b = 0; b < n; ++b) {
    std::uint64_t* at_first = &used[first[b] * words];
    std::uint64_t* at_second = &used[second[b] * words];
    std::size_t w = 0;
    while ((at_first[w] | at_second[w]) == ~std::uint64_t{0}) ++w;  // a free colour exists within `words`
    const std::uint32_t c = std::uint32_t(64 * w) + std::uint32_t(std::countr_one(at_first[w] | at_second[w]));
    colour[b] = c;
    at_first[w] |= std::uint64_t{1} << (c % 64);
    at_second[w] |= std::uint64_t{1} << (c % 64);
    n_colours = std::max(n_colours, c + 1);
  }
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return colour[a] != colour[b] ? colour[a] < colour[b] : first[a] < first[b];
  });
  offsets.assign(n_colours + 1, 0);
  for (std::size_t b = 0; b < n; ++b) ++offsets[colour[b] + 1];
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  threaded = worth_threads(n, n_colours, n_particles);
  return order;
}

std::vector<std::uint32_t> BondSet::order_pairs_by_first(std::size_t n_particles) {
  std::vector<std::uint32_t> order(size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return first_[a] != first_[b] ? first_[a] < first_[b] : second_[a] < second_[b];
  });
  apply_pair_order(order);
  colouring_.offsets.clear();
  colouring_.threaded = BondColouring::worth_threads(size(), 1, n_particles);
  return order;
}

void BondSet::not_a_gather_pass() { throw std::logic_error("BondSet: a gather pass's half called on a set that does not gather"); }

bool gathered_pass_threaded(std::span<const BondSet* const> sets, std::size_t n_particles) {
  std::size_t bonds = 0;
  for (const BondSet* set : sets) bonds += set->size();
  return BondColouring::worth_threads(bonds, 1, n_particles);
}

void accumulate_gathered_forces(std::span<const BondSet* const> sets, ParticleSet& p, const ForceScan& scan) {
  run_threaded_if(gathered_pass_threaded(sets, p.size()), [&] {
    const IndexRange des = thread_share(static_cast<long>(p.size()));
    for (const BondSet* set : sets) set->evaluate_share(p, scan, des);
#pragma omp barrier
    for (const BondSet* set : sets) set->add_share(p, scan, des);
  });
}

void add_bond_end_virial(const ParticleSet& p, std::uint32_t i, std::uint32_t j, const Vec3& f_i, VirialBranch branch,
                         int end, Sym3& virial) {
  const Vec3 r = p.position[j] - p.position[i];
  double share_i = 1.0;  // 2 d_i / d
  if (branch == VirialBranch::radical) {
    const double d2 = norm2(r), ri = p.radius[i], rj = p.radius[j];
    share_i = (d2 + ri * ri - rj * rj) / d2;
  }
  add_symmetric_product(virial, (end == 0 ? share_i : 2.0 - share_i) * r, f_i);
}

void add_bond_virial(const ParticleSet& p, std::uint32_t i, std::uint32_t j, const Vec3& f_i, VirialBranch branch,
                     std::span<Sym3> virial) {
  add_bond_end_virial(p, i, j, f_i, branch, 0, virial[i]);
  add_bond_end_virial(p, i, j, f_i, branch, 1, virial[j]);
}

double BondSet::recorded_energy() const {
  return fixed_order_sum(static_cast<long>(size()), parallel_threshold, sum_partial_,
                         [this](long b) { return energy_record_[static_cast<std::size_t>(b)]; });
}

void BondSet::add_recorded_energy_per_particle(std::span<double> energy) const {
  for (std::size_t b = 0; b < size(); ++b) {
    const double half = 0.5 * energy_record_[b];
    energy[first_[b]] += half;
    energy[second_[b]] += half;
  }
}

void BondSet::save_state(StateArchive& archive, const std::string& prefix) const {
  archive.put(prefix + "first", first_);
  archive.put(prefix + "second", second_);
  archive.put(prefix + "broken", broken_);
  archive.put(prefix + "energy_record", energy_record_);
  save_law_state(archive, prefix);
}

void BondSet::load_state(const StateArchive& archive, const std::string& prefix) {
  if (archive.get<std::uint32_t>(prefix + "first") != first_ || archive.get<std::uint32_t>(prefix + "second") != second_)
    throw StateMismatch("the bonds of '" + prefix + "' join other DEs than this scene's");
  std::vector<std::uint8_t> broken(size());
  archive.get_into(prefix + "broken", broken);
  for (std::size_t b = 0; b < size(); ++b)
    if (broken[b] && !broken_[b]) break_bond(b);
  if (broken != broken_) throw StateMismatch("'" + prefix + "broken' has a bond intact that this scene starts broken");
  archive.get_into(prefix + "energy_record", energy_record_);
  load_law_state(archive, prefix);
}

}  // namespace arlequin::dem
