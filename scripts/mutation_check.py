#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Checks that the tests can fail: each mutant below (one small wrong change to a law, a bound or a
measure) is built, the tests that should see it are run, and it must make one of them fail.

A mutant changes one exact string of one file; the file is restored after its run, whatever
happens, and the build is brought back to the tree as it is at the end. Run it in a scratch
clone with its own build (it rewrites sources and rebuilds): about an hour on two cores.

    git clone . /tmp/mutants && cd /tmp/mutants && scripts/setup.sh
    python3 scripts/mutation_check.py [--build build] [ID ...]    # all mutants, or those named
    python3 scripts/mutation_check.py --list

Each row prints KILLED (a test failed), SURVIVED (none did: a test is missing), or MISSING (its
original string is no longer in the file: update the row). Exit status 1 when a mutant not
marked equivalent survives or a row is missing. docs/validation.md#tests-can-fail has the
reading of the last run.
"""
import argparse
import pathlib
import subprocess
import sys
import time

# Tests left out of every run: minutes each, and the quicker ones named by the rows see the
# same models.
SLOW_TESTS = r"Dcb\.|ZoneMove|RevFailure\.(Reduced|RunsAre)|Calibration|UniformStrainNem"

# id, file, original, mutant, tests (a ctest -R expression), equivalent (why no test can see it,
# or "").
MUTANTS = [
    ("spring_bound_one_end", "dem/bonds/spring_bond.cpp",
     "translational[first_[b]] += stiffness_[b] * (mi + std::sqrt(mi * mj));",
     "translational[first_[b]] += stiffness_[b] * (mi);", "CriticalStep|Spring", ""),
    ("cohesive_bound_no_turn_coupling", "dem/bonds/cohesive_contact.cpp",
     "rotational[i] += K * (ai * ai * Ii + ai * aj * std::sqrt(Ii * Ij)", "rotational[i] += K * (ai * ai * Ii",
     "CriticalStep|Cohesive", ""),
    ("contact_bound_one_mass", "dem/dem_model.cpp",
     "return contact_->stiffness() * contacts * (inv_m + std::sqrt(inv_m * inv_mass_max_));",
     "return contact_->stiffness() * contacts * (inv_m);", "CriticalStep|Contact|Granular", ""),
    ("rdef_average_across_materials", "dem/rdef.cpp", "if (class_[i] != class_[j]) continue;", "", "Rdef|Failure", ""),
    ("rdef_virial_not_halved", "dem/rdef.cpp", "c /= 2.0 * omega[i];", "c /= omega[i];", "Rdef|Failure|Virial", ""),
    ("rdef_sphere_volume", "dem/rdef.cpp", "4.0 / 3.0 * std::numbers::pi", "4.0 / 2.0 * std::numbers::pi", "Rdef|Failure", ""),
    ("rdef_weaker_end", "dem/rdef.cpp", "std::max(equivalent_[i], equivalent_[j])",
     "std::min(equivalent_[i], equivalent_[j])", "Rdef|Failure", ""),
    ("rdef_average_own_volume", "dem/rdef.cpp", "average_[j][c] += omega_[i] * sigma[i][c];",
     "average_[j][c] += omega_[j] * sigma[i][c];", "Rdef|Failure", ""),
    ("von_mises_shear", "dem/failure.cpp", "+ 3.0 * (t[3] * t[3]", "+ 2.0 * (t[3] * t[3]", "Failure|Rdef|EquivalentStress", ""),
    ("principal_scale", "dem/failure.cpp", "return {q, std::sqrt(p2 / 6.0)};", "return {q, std::sqrt(p2 / 5.0)};",
     "Failure|Rdef|EquivalentStress", ""),
    ("crack_tip_half_damaged", "dem/crack_front.cpp", "if (d >= 1.0 || broken[b]) tip[k]",
     "if (d >= 0.5 || broken[b]) tip[k]", "CrackFront|Cohesive", ""),
    ("cohesive_linear_bk", "dem/bonds/cohesive_contact.cpp",
     "const Lanes toughness = q.toughness_I + (q.toughness_II - q.toughness_I) * share;",
     "const Lanes toughness = q.toughness_I + (q.toughness_II - q.toughness_I) * mix;", "Cohesive", ""),
    ("cohesive_damaged_compression", "dem/bonds/cohesive_contact.cpp", "+ n * (K * closing);",
     "+ n * (K * closing * (1.0 - damage));", "Cohesive", ""),
    ("cohesive_dissipation", "dem/bonds/cohesive_contact.cpp", "return (reached - lambda0) / (lambda_f - lambda0);",
     "return (reached - lambda0) / lambda_f;", "Cohesive|Energy", ""),
    ("friction_arm", "dem/contacts/contact_kernel.hpp", "arm_j = n * (half_overlap - p.radius[j]);",
     "arm_j = n * (p.radius[j] - half_overlap);", "Contact|Friction|Granular", ""),
    ("contact_energy_heavier_weight", "dem/contacts/contact_kernel.hpp",
     "(weight.empty() ? 1.0 : std::min(weight[i], weight[j]))",
     "(weight.empty() ? 1.0 : std::max(weight[i], weight[j]))", "Contact|Fabric|Energy|Coupl", ""),
    ("contact_mass_unweighted", "dem/dem_model.cpp",
     "return contact_weight_.empty() ? particles.inv_mass[i] : contact_weight_[i] * particles.inv_mass[i];",
     "return particles.inv_mass[i];", "Contact|Critical|Fabric|Coupl", ""),
    ("damping_work_start_velocity", "dem/dem_model.cpp",
     "return -half_dt * (dot(damping_force_[i], 0.5 * (v + p.velocity[i])) +",
     "return -half_dt * (dot(damping_force_[i], v) +", "Damp|Energy|Balance", ""),
    ("damping_imposed_spin", "dem/dem_model.cpp",
     "damping_torque_[i] = (driven_[i] & 8) ? Vec3{} : p.angular_velocity[i] * (-damping_ * p.inertia(i));",
     "damping_torque_[i] = p.angular_velocity[i] * (-damping_ * p.inertia(i));",
     "Damp|Energy|Balance|Boundary|Driven|Impos",
     "a locked rotation's angular velocity is 0 whenever the damping reads it (the imposed motion "
     "sets it), so its damping torque is 0 either way"),
    ("weave_mass", "dem/weave.cpp", "const double de_mass = yarn_mass / double(y.end - y.first);",
     "const double de_mass = yarn_mass / double(y.end - y.first + 1);", "Weave|Fabric", ""),
    ("cubic_weight", "coupling/overlap_zone.cpp", "return 1.0 - t * t * (3.0 - 2.0 * t);",
     "return 1.0 - t * t * (3.0 - t);", "Overlap|Weight|Arlequin|Patch|Coupl", ""),
    ("coupling_work_doubled", "coupling/coupled_model.cpp", "coupling_work_ -= 0.5 * dt * power;",
     "coupling_work_ -= dt * power;", "Energy|Balance|Coupled|Coupling",
     "G v(n+1/2) = -G v(n-1/2) in this step (docs/theory.md#coupled-step): from a start at rest, "
     "as in every coupled test, the multipliers' work over a drift is round-off, and twice it too"),
    ("transverse_shear_compliance", "continuum/material.cpp", "S(3, 3) = 2 * (1 + nu_TT) / E_T;",
     "S(3, 3) = (1 + nu_TT) / E_T;", "Material|Transvers|Isotrop|Continuum", ""),
    ("transverse_poisson", "continuum/material.cpp",
     "S(0, 1) = S(1, 0) = S(0, 2) = S(2, 0) = -nu_LT / E_L;",
     "S(0, 1) = S(1, 0) = S(0, 2) = S(2, 0) = -nu_LT / E_T;", "Material|Transvers|Isotrop|Continuum", ""),
    ("orthotropic_poisson", "continuum/material.cpp", "S(1, 2) = S(2, 1) = -nu[2] / E[1];",
     "S(1, 2) = S(2, 1) = -nu[2] / E[2];", "Material|Ortho|Continuum|Fabric", ""),
    ("isotropic_lambda", "continuum/material.cpp", "const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu))",
     "const double lambda = E * nu / ((1 + nu) * (1 - nu))", "Material|Isotrop|Continuum|Fe|Nem", ""),
    ("p2_corner_mass", "continuum/fe/fe_solver.cpp", "for (int a = 0; a < 4; ++a) m[t[a]] += me / 36.0;",
     "for (int a = 0; a < 4; ++a) m[t[a]] += me / 30.0;", "Mass|Fe|Continuum", ""),
    ("p1_mass_unweighted", "continuum/fe/fe_solver.cpp", "for (int a = 0; a < 4; ++a) m[t[a]] += w * l[a];",
     "for (int a = 0; a < 4; ++a) m[t[a]] += w * 0.25;", "WeightedLumpedMass|ContinuumFe", ""),
]


def run(cmd, cwd):
    return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("ids", nargs="*", help="mutants to run (default: all)")
    parser.add_argument("--build", default="build", help="the build folder, relative to the tree (default: build)")
    parser.add_argument("--list", action="store_true", help="list the mutants and exit")
    args = parser.parse_args()
    root = pathlib.Path(__file__).resolve().parent.parent
    known = {m[0] for m in MUTANTS}
    unknown = [i for i in args.ids if i not in known]
    if unknown:
        sys.exit(f"mutation_check: unknown mutant(s) {', '.join(unknown)}; --list names them")
    chosen = [m for m in MUTANTS if not args.ids or m[0] in args.ids]
    if args.list:
        for mid, path, _, _, tests, equivalent in chosen:
            print(f"{mid:34s} {path:34s} {tests}{'  (equivalent)' if equivalent else ''}")
        return 0
    build = str(args.build)
    if not (root / build / "CMakeCache.txt").exists():
        sys.exit(f"mutation_check: {root / build} is not a configured build folder (run scripts/setup.sh)")
    failures = 0
    try:
        for mid, path, original, mutant, tests, equivalent in chosen:
            source = root / path
            text = source.read_text()
            if text.count(original) != 1:
                print(f"{mid}: MISSING (the original is in {path} {text.count(original)} times, not once)", flush=True)
                failures += 1
                continue
            start = time.monotonic()
            try:
                source.write_text(text.replace(original, mutant))
                built = run(["cmake", "--build", build, "-j2"], root)
                if built.returncode != 0:
                    print(f"{mid}: does not build (fix the row)\n{built.stdout[-2000:]}", flush=True)
                    failures += 1
                    continue
                ran = run(["ctest", "--test-dir", build, "-LE", "validation", "-R", tests, "-E", SLOW_TESTS, "-j2",
                           "--timeout", "900"], root)
            finally:
                source.write_text(text)
            failed = [line.split("Test")[1].split()[1] for line in ran.stdout.splitlines() if "***" in line]
            count = next((line.strip() for line in ran.stdout.splitlines() if "tests passed" in line), "no tests ran")
            seconds = time.monotonic() - start
            if ran.returncode != 0 and "No tests were found" not in ran.stdout + ran.stderr:
                print(f"{mid}: KILLED by {', '.join(failed[:3]) or 'ctest'} ({count}; {seconds:.0f} s)", flush=True)
            elif equivalent:
                print(f"{mid}: survived, equivalent: {equivalent}", flush=True)
            else:
                print(f"{mid}: SURVIVED ({count}; {seconds:.0f} s): no test sees {path}: {mutant!r}", flush=True)
                failures += 1
    finally:
        run(["cmake", "--build", build, "-j2"], root)  # the binaries of the tree as it is
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
