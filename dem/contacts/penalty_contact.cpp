// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/contacts/penalty_contact.hpp"

#include "common/case_file.hpp"

namespace arlequin::dem {

constexpr KeyDoc penalty_keys[] = {
    {"stiffness", KeyType::number, "N/m", Range::positive(), "(a weave: its springs' K_mu; else required)", "normal stiffness k: f = k x overlap of the two spheres"},
    {"friction", KeyType::number, "1", Range::non_negative(), "0", "Coulomb coefficient mu of the tangential force (0: frictionless)"},
    {"slip_velocity", KeyType::number, "m/s", Range::positive(), "0.001", "sliding speed below which friction is viscous (regularisation)"},
};
std::span<const KeyDoc> PenaltyContact::keys() { return penalty_keys; }

std::unique_ptr<ContactLaw> PenaltyContact::make(CaseNode& section, const ContactDefaults& defaults) {
  const double stiffness = defaults.stiffness > 0.0 && !section.has("stiffness") ? defaults.stiffness
                                                                                 : section.number("stiffness", Range::positive(), "N/m");
  const double friction = section.number_or("friction", 0.0, Range::non_negative(), "1");
  return std::make_unique<PenaltyContact>(stiffness, friction,
                                          section.number_or("slip_velocity", 1e-3, Range::positive(), "m/s"));
}

}  // namespace arlequin::dem
