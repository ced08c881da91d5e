// SPDX-License-Identifier: GPL-3.0-or-later
// ContinuumPart for builds configured with ARLEQUIN_WITH_CONTINUUM=OFF: a case that asks for a
// continuum gets a clear error instead of a link failure.
#include "app/continuum_part.hpp"

#include "common/case_file.hpp"

namespace arlequin::app {

// Without a continuum no case reads these sections: none to declare.
std::span<const SchemaSection> ContinuumPart::schema() { return {}; }

std::unique_ptr<ContinuumPart> ContinuumPart::read(CaseNode section, std::optional<CaseNode>, const std::string&) {
  section.fail("solver", "this build has no continuum solvers (configure with -DARLEQUIN_WITH_CONTINUUM=ON)");
}

}  // namespace arlequin::app
