#include "dem/spring_bond.hpp"

#include <cmath>

#include "common/case_file.hpp"

namespace arlequin::dem {

std::unique_ptr<BondSet> SpringBondSet::make(CaseNode& section) {
  return std::make_unique<SpringBondSet>(section.number("stiffness", Range::positive(), "N/m"));
}

void SpringBondSet::add(std::uint32_t i, std::uint32_t j, const ParticleSet& p) {
  first_.push_back(i);
  second_.push_back(j);
  rest_length_.push_back(norm(p.position[j] - p.position[i]));
  stiffness_.push_back(nominal_stiffness_);
}

void SpringBondSet::scale_stiffness(std::span<const double> factor) {
  for (std::size_t b = 0; b < size(); ++b) stiffness_[b] *= factor[b];
}

void SpringBondSet::finalize(std::size_t n_particles) {
  const auto order = colouring_.build(first_, second_, n_particles);
  apply_order(first_, order);
  apply_order(second_, order);
  apply_order(rest_length_, order);
  apply_order(stiffness_, order);
}

void SpringBondSet::accumulate_forces(ParticleSet& p) const {
  for_each_bond(colouring_, [&](std::size_t b) {
    const std::uint32_t i = first_[b], j = second_[b];
    const Vec3 d = p.position[j] - p.position[i];
    const double L = norm(d);
    const Vec3 f_j = d * (-stiffness_[b] * (L - rest_length_[b]) / L);
    p.force[i] -= f_j;
    p.force[j] += f_j;
  });
}

double SpringBondSet::energy(const ParticleSet& p) const {
  double e = 0.0;
  for (std::size_t b = 0; b < size(); ++b) {
    const double stretch = norm(p.position[second_[b]] - p.position[first_[b]]) - rest_length_[b];
    e += 0.5 * stiffness_[b] * stretch * stretch;
  }
  return e;
}

void SpringBondSet::add_frequency_bounds(const ParticleSet& p, std::span<double> translational,
                                         std::span<double>) const {
  for (std::size_t b = 0; b < size(); ++b) {
    const double mi = p.inv_mass[first_[b]], mj = p.inv_mass[second_[b]];
    translational[first_[b]] += stiffness_[b] * (mi + std::sqrt(mi * mj));
    translational[second_[b]] += stiffness_[b] * (mj + std::sqrt(mi * mj));
  }
}

}  // namespace arlequin::dem
