#include "dem/contacts/penalty_contact.hpp"

#include "common/case_file.hpp"

namespace arlequin::dem {

constexpr KeyDoc penalty_keys[] = {
    {"stiffness", KeyType::number, "N/m", Range::positive(), "", "normal stiffness k: f = k x overlap of the two spheres"},
};
std::span<const KeyDoc> PenaltyContact::keys() { return penalty_keys; }

std::unique_ptr<ContactLaw> PenaltyContact::make(CaseNode& section) {
  return std::make_unique<PenaltyContact>(section.number("stiffness", Range::positive(), "N/m"));
}

}  // namespace arlequin::dem
