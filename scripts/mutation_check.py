#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Checks that the tests can fail: each mutant below (one small wrong change to a law, a bound or a
measure) is built, the tests that should see it are run, and it must make one of them fail.

A mutant changes one exact string of one file; the file is restored after its run, whatever
happens, and the build is brought back to the tree as it is at the end. Run it in a scratch
clone with its own build (it rewrites sources and rebuilds): about two hours on two cores.

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
import re
import subprocess
import sys
import time

# Tests left out of every run: minutes each, and the quicker ones named by the rows see the
# same models.
SLOW_TESTS = r"Dcb\.|ZoneMove|RevFailure\.(Reduced|RunsAre)|Calibration|UniformStrainNem"

# id, file, original, mutant, tests (a ctest -R expression; with a leading "!" it names slow
# tests on purpose and SLOW_TESTS is not left out), equivalent (why no test can see it, or "").
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
    ("h1_length_not_squared", "coupling/coupling_operators.cpp",
     "S += settings.length * settings.length * gradient_gram(x, op.weight, radius);",
     "S += settings.length * gradient_gram(x, op.weight, radius);", "H1|Coupl|Patch|Operator", ""),
    ("gradient_without_centre", "coupling/coupling_operators.cpp", "trip[k].emplace_back(p, p, -g[k]);", "",
     "H1|Coupl|Patch|Operator", ""),
    ("coarse_mediator_unweighted", "coupling/coupling_operators.cpp",
     "const SparseMatrix NtS = R * SparseMatrix(op.N.transpose()) * S;",
     "const SparseMatrix NtS = R * SparseMatrix(op.N.transpose());", "Coarse|Mediator|Coupl|Patch|Operator", ""),
    ("coupled_share_unweighted", "coupling/coupling_operators.cpp", "op.weight.push_back(share[k]);",
     "op.weight.push_back(1.0);", "Coupl|Patch|Operator|Mediator", ""),
    ("woodbury_impulse_without_g", "coupling/multiplier_solver.cpp",
     "if (impulse) impulse->dem(r, c) = a.g[r] * multiplier * rate;",
     "if (impulse) impulse->dem(r, c) = multiplier * rate;", "CouplingMultiplierSolver", ""),
    ("woodbury_held_share_left_out", "coupling/multiplier_solver.cpp",
     "a.inv_D[r] * (a.g[r] * vd(r, c) + held_share(r, c))", "a.inv_D[r] * (a.g[r] * vd(r, c))",
     "CouplingMultiplierSolver|FabricCoupled|Coupl", ""),
    ("backward_solve_partial_sum_dropped", "coupling/multiplier_solver.cpp",
     "Row total = sums == 4 ? (sum[0][c] + sum[1][c]) + (sum[2][c] + sum[3][c])",
     "Row total = sums == 4 ? (sum[0][c] + sum[1][c]) + sum[2][c]", "CouplingMultiplierSolver|Coupl", ""),
    ("factor_path_rate_left_out", "coupling/multiplier_solver.cpp", "  dd *= rate;\n  lambda *= rate;",
     "  lambda *= rate;", "CouplingMultiplierSolver|Coupl|Patch", ""),
    ("substep_kinetic_whole_impulse", "coupling/coupled_model.cpp",
     "return continuum_.kinetic_energy(j == 0 ? 0.0 : -(0.5 * m - j) * dem_.last_dt());",
     "return continuum_.kinetic_energy(j == 0 ? 0.0 : -(0.5 * m) * dem_.last_dt());",
     "Substep|Forced|Energy|Coupl|Fabric", ""),
    ("overlap_damage_half_weight", "coupling/coupled_model.cpp", "if (!(weight < 1.0)) continue;",
     "if (!(weight < 0.5)) continue;", "Damage|Overlap|Coupl|Fabric", ""),
    ("held_failures_half_weight", "coupling/coupled_model.cpp",
     "return zone_.alpha_d(0.5 * (reference[set.first()[b]] + reference[set.second()[b]])) < 1.0;",
     "return zone_.alpha_d(0.5 * (reference[set.first()[b]] + reference[set.second()[b]])) < 0.5;",
     "Hold|Damage|Overlap|Coupl|Fabric", ""),
    ("arrest_work_not_booked", "coupling/coupled_model.cpp", "coupling_work_ += kinetic() - before;", "",
     "Arrest|Energy|Coupl|Fabric", ""),
    ("consistent_quadrature_unweighted", "coupling/coupled_model.cpp",
     "h += zone_.alpha_d(f.centroid) * f.area;", "h += f.area;", "Quadrature|Consistent|Patch|Coupl", ""),
    ("acceleration_norm_unconstrained", "coupling/coupled_model.cpp",
     "sum += (norm2(constrained) - norm2(a)) / P.inv_mass[i];", "", "Relax|Accel|Coupl|Static", ""),
    ("linear_weight", "coupling/overlap_zone.cpp", "case WeightShape::linear: return 1.0 - t;",
     "case WeightShape::linear: return 1.0 - t * t;", "Overlap|Weight|Arlequin|Patch|Coupl", ""),
    ("overlap_volume_terms_unsigned", "coupling/overlap_zone.cpp",
     "v += term.sign * volume(clipped(cell, term.planes));", "v += volume(clipped(cell, term.planes));",
     "Overlap|Shell|Fabric|Coupl", ""),
    ("nem_stabilization_not_rooted", "continuum/nem/nem_solver.cpp",
     "const double root_a = std::sqrt(settings.nem_stabilization);",
     "const double root_a = settings.nem_stabilization;", "Nem|Stabil", ""),
    ("nem_point_at_face_centroid", "continuum/nem/nem_solver.cpp",
     "s_m.moment += (0.25 * v) * (X[i] + c + a + b);", "s_m.moment += (v / 3.0) * (c + a + b);", "Nem|Coupl", ""),
    ("nem_mass_unweighted", "continuum/nem/nem_solver.cpp",
     "m[i] = alpha(nodes()[i]) * node_density_[i] * cell_volume_[i];", "m[i] = node_density_[i] * cell_volume_[i];",
     "Nem|Mass|Coupl", ""),
    ("nem_density_plain_mean", "continuum/nem/nem_solver.cpp",
     ": (node_density_[i] * (cell_volume_[i] - volume) + density * volume) / cell_volume_[i];",
     ": 0.5 * (node_density_[i] + density);", "Nem|Density|Material|Join", ""),
    ("nem_edge_coordinates_swapped", "continuum/nem/nem_solver.cpp",
     "out.push_back({lo, shi / (shi - slo)});", "out.push_back({lo, -slo / (shi - slo)});", "Nem|Natural|Interp", ""),
    ("continuum_kinetic_kick_sign", "continuum/continuum_solver.cpp",
     "const double v = is_fixed_[d] ? v_[d] : v_[d] + kick * f_[d] / dof_mass_[d];",
     "const double v = is_fixed_[d] ? v_[d] : v_[d] - kick * f_[d] / dof_mass_[d];",
     "Substep|Forced|Energy|Coupl|Continuum", ""),
    ("beam_torsion_polar_moment", "dem/bonds/beam_bond.cpp", "const double J = 2.0 * I;", "const double J = I;",
     "TwoDEs|BeamBond|Beam|Torsion", ""),
    ("beam_end_moments_swapped", "dem/bonds/beam_bond.cpp",
     "const LaneVec torque_on_j = -bending * (theta_a + 2.0 * theta_b) - torsion_moment * axis;",
     "const LaneVec torque_on_j = -bending * (2.0 * theta_a + theta_b) - torsion_moment * axis;", "BeamBond|Beam", ""),
    ("beam_energy_without_cross_term", "dem/bonds/beam_bond.cpp",
     "bending_[b] * (norm2(a.theta_a) + dot(a.theta_a, a.theta_b) + norm2(a.theta_b))",
     "bending_[b] * (norm2(a.theta_a) + norm2(a.theta_b))", "BeamBond|Beam|Energy", ""),
    ("beam_bending_stress_lesser_end", "dem/bonds/beam_bond.cpp", "(end_a < end_b ? end_b : end_a)",
     "(end_a < end_b ? end_a : end_b)", "BeamBond|Beam|Failure|Bbf|Rev", ""),
    ("beam_shear_stress_factor", "dem/bonds/beam_bond.cpp", "const double shear = 1.5 * E * rb * rb",
     "const double shear = 0.5 * E * rb * rb", "BreakablePair|BeamFailure|Beam", ""),
    ("beam_torsion_stress_halved", "dem/bonds/beam_bond.cpp", "const double torsion = G * rb * std::abs(a.twist) / L0;",
     "const double torsion = 0.5 * G * rb * std::abs(a.twist) / L0;", "BreakablePair|BeamFailure|Beam", ""),
    ("spring_elongation_over_length", "dem/bonds/spring_bond.hpp",
     "return e.length / rest_length_[b] - 1.0; }", "return 1.0 - rest_length_[b] / e.length; }",
     "Spring|Yarn|Fabric|Weave", ""),
    ("friction_power_sign", "dem/contacts/contact_kernel.hpp", "return -dot(f_t, v_t);", "return dot(f_t, v_t);",
     "Friction|Contact|Energy|Granular", ""),
    ("rotation_in_body_frame", "dem/particles.cpp",
     "else q[l] = renormalized(from_rotation_vector(omega[l] * dt) * q[l]);",
     "else q[l] = renormalized(q[l] * from_rotation_vector(omega[l] * dt));", "FreeMotion|Quat", ""),
    ("laguerre_radii_sign", "dem/laguerre_cells.cpp",
     "const double offset = (norm2(c[j]) - norm2(c[i]) - r[j] * r[j] + r[i] * r[i]) / (2.0 * d);",
     "const double offset = (norm2(c[j]) - norm2(c[i]) + r[j] * r[j] - r[i] * r[i]) / (2.0 * d);",
     "Laguerre|Rdef|Overlap", ""),
    ("compare_resample_weights_swapped", "app/compare.cpp", "out.push_back((1 - w) * b[k - 1] + w * b[k]);",
     "out.push_back(w * b[k - 1] + (1 - w) * b[k]);", "Cli|Compare|Sweep", ""),
    ("compare_reference_of_the_other", "app/compare.cpp", "max_ref = std::max(max_ref, std::abs(va[k]));",
     "max_ref = std::max(max_ref, std::abs(vb[k]));", "Cli|Compare|Sweep", ""),
    ("compare_rms_not_rooted", "app/compare.cpp", "std::sqrt(sum_diff / std::max(sum_ref, 1e-300))",
     "sum_diff / std::max(sum_ref, 1e-300)", "Cli|Compare|Sweep", ""),
    ("compare_compute_with_output", "app/compare.cpp", "double compute_seconds() const { return loop - output; }",
     "double compute_seconds() const { return loop; }", "Cli|Compare|Sweep", ""),
    ("compare_first_break_over_other", "app/compare.cpp",
     "return (*b.first_break - *a.first_break) / *a.first_break;",
     "return (*b.first_break - *a.first_break) / *b.first_break;", "Cli|Compare|Sweep", ""),
    ("driven_work_end_reaction", "dem/dem_model.cpp",
     "external_work_ += dot(0.5 * (reaction + constraint_reaction_[k]), p.velocity[i]) * last_dt_;",
     "external_work_ += dot(reaction, p.velocity[i]) * last_dt_;", "Boundary|Driven|Balance|Energy|Impos|Clamp", ""),
    ("load_work_halved", "dem/dem_model.cpp",
     "external_work_ += dot(load_per_particle_[k], p.velocity[i]) * last_dt_;",
     "external_work_ += 0.5 * dot(load_per_particle_[k], p.velocity[i]) * last_dt_;", "Load|Balance|Energy|Force|Cases", ""),
    ("gravity_on_imposed_components", "dem/dem_model.cpp",
     "if (!imposes(i, k)) p.force[i][k] += p.mass(i) * gravity_[k];", "p.force[i][k] += p.mass(i) * gravity_[k];",
     "Gravity|Boundary|Reaction",
     "the reactions are recorded before gravity is added (docs/theory.md#step, steps 7 and 8), the "
     "gravity's work leaves imposed components out, and an imposed velocity is set after the kick (step 10): "
     "gravity on an imposed component changes no motion, reaction, energy or output"),
    ("reaction_sign", "dem/dem_model.cpp", "for (const auto& [i, group] : watched_members_) reaction_[group] -= p.force[i];",
     "for (const auto& [i, group] : watched_members_) reaction_[group] += p.force[i];",
     "Reaction|Boundary|Cases|VirtualTests|Sensor", ""),
    ("group_energy_whole_bond", "dem/bonds/bond_set.cpp", "const double half = 0.5 * energy_record_[b];",
     "const double half = energy_record_[b];", "BondedPair|Sensor|Energy|Group", ""),
    ("affine_modulus_halved", "app/virtual_tests.cpp", "return 2.0 * energy / (strain * strain * g.volume());",
     "return energy / (strain * strain * g.volume());", "VirtualTests", ""),
    ("process_zone_sign", "app/runner.cpp", "case Sensor::CrackQuantity::process_zone: return m.damage_front - m.tip;",
     "case Sensor::CrackQuantity::process_zone: return m.tip - m.damage_front;", r"!Dcb\.ReducedDcbPropagates", ""),
    ("crack_growth_from_zero", "app/runner.cpp", "case Sensor::CrackQuantity::crack_growth: return m.tip - c.initial_tip;",
     "case Sensor::CrackQuantity::crack_growth: return m.tip;", r"!Dcb\.ReducedDcbPropagates", ""),
    ("rotation_series_term", "common/quat.hpp", "0.5 - a2 * one_48th * (1.0 - a2 * one_80th)", "0.5 - a2 * one_48th",
     "FreeMotion|Quat", ""),
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
                slow = [] if tests.startswith("!") else ["-E", SLOW_TESTS]
                ran = run(["ctest", "--test-dir", build, "-LE", "validation", "-R", tests.lstrip("!"), *slow, "-j2",
                           "--timeout", "900"], root)
            finally:
                source.write_text(text)
            failed = [m.group(1) for m in re.finditer(r"Test +#\d+: (\S+) .*\*\*\*", ran.stdout)]
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
