// The explicit registry of bond laws: one row per law, keyed by its case-file name.
#include "common/registry.hpp"
#include "dem/beam_bond.hpp"
#include "dem/spring_bond.hpp"

namespace arlequin::dem {

std::span<const BondLawEntry> bond_laws() {
  static const BondLawEntry table[] = {
      {"beam", "cohesive Euler-Bernoulli beam (Andre et al. 2012): E_mu, nu_mu, r_mu", &BeamBondSet::make},
      {"spring", "axial spring for yarns (seed Eq. 6): stiffness", &SpringBondSet::make},
  };
  return table;
}

std::unique_ptr<BondSet> make_bond_set(CaseNode& section) {
  return choose_entry(bond_laws(), section, "law").make(section);
}

}  // namespace arlequin::dem
