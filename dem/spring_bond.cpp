#include "dem/spring_bond.hpp"

#include <cmath>
#include <stdexcept>

#include "common/case_file.hpp"

namespace arlequin::dem {

std::unique_ptr<BondSet> SpringBondSet::make(CaseNode& section) {
  const double stiffness = section.number("stiffness", Range::positive(), "N/m");
  return std::make_unique<SpringBondSet>(stiffness, section.number_or("max_elongation", 0.0, Range::non_negative(), "1"));
}

void SpringBondSet::add(std::uint32_t i, std::uint32_t j, const ParticleSet& p) {
  add_pair(i, j);
  rest_length_.push_back(norm(p.position[j] - p.position[i]));
  stiffness_.push_back(nominal_stiffness_);
}

void SpringBondSet::scale_stiffness(std::span<const double> factor) {
  for (std::size_t b = 0; b < size(); ++b) stiffness_[b] *= factor[b];
}

void SpringBondSet::finalize(std::size_t n_particles) {
  const auto order = order_pairs(n_particles);
  apply_order(rest_length_, order);
  apply_order(stiffness_, order);
  elongation_.assign(size(), 0.0);
}

SpringBondSet::Stretch SpringBondSet::stretch(std::size_t b, const ParticleSet& p) const {
  const Vec3 d = p.position[second_[b]] - p.position[first_[b]];
  return {d, norm(d)};
}

Vec3 SpringBondSet::force_on_j(std::size_t b, const Stretch& s) const {
  return s.d * (-stiffness_[b] * (s.length - rest_length_[b]) / s.length);
}

Vec3 SpringBondSet::force_on_j(std::size_t b, const ParticleSet& p) const { return force_on_j(b, stretch(b, p)); }

void SpringBondSet::accumulate_forces(ParticleSet& p, const ForceScan& scan) const {
  const auto add_force = [&p, this](std::size_t b, const Vec3& f_j) {
    p.force[first_[b]] -= f_j;
    p.force[second_[b]] += f_j;
  };
  const bool criterion = scan.criterion && has_strength(), virial = !scan.virial.empty(), energy = scan.energy;
  if (!criterion && !virial && !energy) {  // the plain pass: no test per bond (as BeamBondSet)
    for_each_bond(colouring_, [&](std::size_t b) { add_force(b, force_on_j(b, p)); });
    return;
  }
  for_each_bond(colouring_, [&](std::size_t b) {
    const Stretch s = stretch(b, p);
    const Vec3 f_j = force_on_j(b, s);
    add_force(b, f_j);
    if (criterion) elongation_[b] = s.length / rest_length_[b] - 1.0;
    if (energy) energy_record_[b] = energy_of(b, s);
    if (virial && !broken_[b]) add_bond_virial(p, first_[b], second_[b], -f_j, scan.branch, scan.virial);
  });
}

double SpringBondSet::energy_of(std::size_t b, const Stretch& s) const {
  const double stretch = s.length - rest_length_[b];
  return 0.5 * stiffness_[b] * stretch * stretch;
}

double SpringBondSet::bond_energy(std::size_t b, const ParticleSet& p) const { return energy_of(b, stretch(b, p)); }

double SpringBondSet::energy(const ParticleSet& p) const {
  return fixed_order_sum(static_cast<long>(size()), parallel_threshold, sum_partial_,
                         [&](long b) { return bond_energy(static_cast<std::size_t>(b), p); });
}

void SpringBondSet::record_energies(const ParticleSet& p) const {
  record_each([&](std::size_t b) { return bond_energy(b, p); });
}

void SpringBondSet::find_failures(const ParticleSet& p, std::uint32_t set_index, double time,
                                  std::vector<BreakEvent>& events) const {
  if (!has_strength()) return;
  if (elongation_.size() != size()) throw std::logic_error("SpringBondSet::find_failures: bonds added after finalize()");
  for (std::size_t b = 0; b < size(); ++b) {
    if (broken_[b]) continue;
    if (elongation_[b] >= max_elongation_)
      events.push_back({time, set_index, static_cast<std::uint32_t>(b), FailureCriterion::elongation,
                        FailureMode::tension, elongation_[b], bond_energy(b, p)});
  }
}

void SpringBondSet::accumulate_virial(const ParticleSet& p, VirialBranch branch, std::span<Sym3> virial) const {
  for (std::size_t b = 0; b < size(); ++b)
    if (!broken_[b]) add_bond_virial(p, first_[b], second_[b], -force_on_j(b, p), branch, virial);  // the bond pulls i with -force_on_j
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
