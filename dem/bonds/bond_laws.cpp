// SPDX-License-Identifier: GPL-3.0-or-later
// The explicit registry of bond laws: one row per law, keyed by its case-file name.
// To add a law: (1) write dem/bonds/NAME_bond.hpp/.cpp, a class deriving from
// BondKernelSet<Class> with the kernel listed in bond_kernel_set.hpp, a static make(section)
// that reads its parameters and a static keys() that declares them; (2) add its row below;
// (3) test it on two DEs against its closed form.
#include "common/registry.hpp"
#include "dem/bonds/beam_bond.hpp"
#include "dem/bonds/cohesive_contact.hpp"
#include "dem/bonds/spring_bond.hpp"

namespace arlequin::dem {

std::span<const BondLawEntry> bond_laws() {
  static const BondLawEntry table[] = {
      {"beam", "cohesive Euler-Bernoulli beam (Andre et al. 2012): E_mu, nu_mu, r_mu, sigma_f", &BeamBondSet::make, &BeamBondSet::keys},
      {"spring", "axial spring for yarns (seed Eq. 6): stiffness, max_elongation", &SpringBondSet::make, &SpringBondSet::keys},
      {"cohesive_bilinear", "bilinear cohesive contact across an interface (seed Eq. 2, mixed mode B-K): sigma_max, G_I, stiffness, precrack",
       &CohesiveContactSet::make, &CohesiveContactSet::keys},
  };
  return table;
}

std::unique_ptr<BondSet> make_bond_set(CaseNode& section) {
  return choose_entry(bond_laws(), section, "law", "bond").make(section);
}

}  // namespace arlequin::dem
