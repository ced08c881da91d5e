// The explicit registry of contact laws: one row per law, keyed by its case-file name.
#include "common/registry.hpp"
#include "dem/penalty_contact.hpp"

namespace arlequin::dem {

std::span<const ContactLawEntry> contact_laws() {
  static const ContactLawEntry table[] = {
      {"penalty", "linear penalty normal contact (seed Eq. 9): stiffness", &PenaltyContact::make},
  };
  return table;
}

std::unique_ptr<ContactLaw> make_contact_law(CaseNode& section) {
  return choose_entry(contact_laws(), section, "law").make(section);
}

}  // namespace arlequin::dem
