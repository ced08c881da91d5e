// SPDX-License-Identifier: GPL-3.0-or-later
// Contact laws act on the pairs of a NeighbourList.
//
// Contract: accumulate_forces() adds forces/torques for every listed pair that is actually
// touching (|x_i - x_j| < R_i + R_j) and returns the power its friction dissipates at the
// present velocities (W, >= 0; 0 for a frictionless law); energy() is the elastic energy of
// those contacts; stiffness() is the largest normal stiffness a contact can have (N/m), for the
// critical time step. One virtual call per batch of pairs, none per pair.
#pragma once
#include <memory>
#include <span>
#include <string_view>

#include "common/schema.hpp"
#include "dem/neighbour_list.hpp"
#include "dem/particles.hpp"

namespace arlequin {
class CaseNode;
}

namespace arlequin::dem {

class ContactLaw {
 public:
  virtual ~ContactLaw() = default;
  virtual std::string_view law() const = 0;
  virtual double accumulate_forces(const NeighbourList& list, ParticleSet& p) const = 0;
  virtual double energy(const NeighbourList& list, const ParticleSet& p) const = 0;
  virtual double stiffness() const = 0;
};

// Registry of contact laws, keyed by the case-file name (dem.contact.law).
struct ContactLawEntry {
  std::string_view name;
  std::string_view summary;
  std::unique_ptr<ContactLaw> (*make)(CaseNode& parameters);
  std::span<const KeyDoc> (*keys)();  // its own keys: schema section "contact (law: name)"
};
std::span<const ContactLawEntry> contact_laws();
std::unique_ptr<ContactLaw> make_contact_law(CaseNode& contact_section);

}  // namespace arlequin::dem
