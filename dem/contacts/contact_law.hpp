// SPDX-License-Identifier: GPL-3.0-or-later
// Contact laws act on the pairs of a NeighbourList.
//
// Contract: accumulate_forces() adds forces/torques for every listed pair that is actually
// touching (|x_i - x_j| < R_i + R_j) and returns the power its friction dissipates at the
// present velocities (W, >= 0; 0 for a frictionless law) and the deepest contact (its overlap
// over the pair's smaller radius, and the pair; among the pairs of weight 1 when weighted,
// below), and adds one to touching[i] and touching[j]
// for each touching pair (touching: one count per DE, zeroed by the caller; empty: not
// counted); energy() is the elastic energy of
// those contacts; stiffness() is the largest normal stiffness a contact can have (N/m), for the
// critical time step. One virtual call per batch of pairs, none per pair.
// Arlequin weight (weight: one per DE, or empty for none): a pair's force, friction and
// energy are scaled by the smaller of its two DEs' weights, a constant per pair, so the
// weighted force stays the gradient of the weighted energy (docs/theory.md#weighted-models).
#pragma once
#include <cstdint>
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

// What one contact pass found besides its forces.
struct ContactPass {
  double friction_power = 0.0;  // W, >= 0
  double deepest = 0.0;         // largest overlap / min(R_i, R_j) over the touching pairs
  std::uint32_t first = 0, second = 0;  // that pair
  std::size_t touching = 0;     // touching pairs
};

class ContactLaw {
 public:
  virtual ~ContactLaw() = default;
  virtual std::string_view law() const = 0;
  virtual ContactPass accumulate_forces(const NeighbourList& list, ParticleSet& p, std::span<std::uint32_t> touching = {},
                                        std::span<const double> weight = {}) const = 0;
  virtual double energy(const NeighbourList& list, const ParticleSet& p, std::span<const double> weight = {}) const = 0;
  virtual double stiffness() const = 0;
};

// What the sample suggests for keys the case leaves out: a weave's contacts take its springs'
// stiffness (seed, below Eq. 9). 0: no suggestion, the key is required.
struct ContactDefaults {
  double stiffness = 0.0;  // N/m
};

// Registry of contact laws, keyed by the case-file name (dem.contact.law).
struct ContactLawEntry {
  std::string_view name;
  std::string_view summary;
  std::unique_ptr<ContactLaw> (*make)(CaseNode& parameters, const ContactDefaults& defaults);
  std::span<const KeyDoc> (*keys)();  // its own keys: schema section "contact (law: name)"
};
std::span<const ContactLawEntry> contact_laws();
std::unique_ptr<ContactLaw> make_contact_law(CaseNode& contact_section, const ContactDefaults& defaults = {});

}  // namespace arlequin::dem
