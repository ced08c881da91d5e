// SPDX-License-Identifier: GPL-3.0-or-later
// The explicit registry of contact laws: one row per law, keyed by its case-file name.
// To add a law: (1) write dem/contacts/NAME_contact.hpp/.cpp, a class deriving from
// ContactKernelLaw<Class> with the kernel listed in contact_kernel.hpp, a static make(section)
// that reads its parameters and a static keys() that declares them; (2) add its row below;
// (3) test it on two DEs against its closed form.
#include "common/registry.hpp"
#include "dem/contacts/penalty_contact.hpp"

namespace arlequin::dem {

std::span<const ContactLawEntry> contact_laws() {
  static const ContactLawEntry table[] = {
      {"penalty", "linear penalty contact (seed Eq. 9), regularised Coulomb friction: stiffness, friction", &PenaltyContact::make, &PenaltyContact::keys},
  };
  return table;
}

std::unique_ptr<ContactLaw> make_contact_law(CaseNode& section, const ContactDefaults& defaults) {
  return choose_entry(contact_laws(), section, "law", "contact").make(section, defaults);
}

}  // namespace arlequin::dem
