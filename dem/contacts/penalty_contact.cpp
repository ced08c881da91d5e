#include "dem/contacts/penalty_contact.hpp"

#include <cmath>

#include "common/case_file.hpp"

namespace arlequin::dem {

constexpr KeyDoc penalty_keys[] = {
    {"stiffness", KeyType::number, "N/m", Range::positive(), "", "normal stiffness k: f = k x overlap of the two spheres"},
};
std::span<const KeyDoc> PenaltyContact::keys() { return penalty_keys; }

std::unique_ptr<ContactLaw> PenaltyContact::make(CaseNode& section) {
  return std::make_unique<PenaltyContact>(section.number("stiffness", Range::positive(), "N/m"));
}

void PenaltyContact::accumulate_forces(const NeighbourList& list, ParticleSet& p) const {
  for (auto [i, j] : list.pairs()) {
    const Vec3 d = p.position[j] - p.position[i];
    const double reach = p.radius[i] + p.radius[j];
    const double dist2 = norm2(d);
    if (dist2 >= reach * reach) continue;
    const double dist = std::sqrt(dist2);
    const Vec3 f_j = d * (stiffness_ * (reach - dist) / dist);
    p.force[i] -= f_j;
    p.force[j] += f_j;
  }
}

double PenaltyContact::energy(const NeighbourList& list, const ParticleSet& p) const {
  double e = 0.0;
  for (auto [i, j] : list.pairs()) {
    const double overlap = p.radius[i] + p.radius[j] - norm(p.position[j] - p.position[i]);
    if (overlap > 0.0) e += 0.5 * stiffness_ * overlap * overlap;
  }
  return e;
}

}  // namespace arlequin::dem
