// SPDX-License-Identifier: GPL-3.0-or-later
// A DEM zone that follows a crack: the band of coupling.overlap.band.follow moves along, ahead of
// the DEM interface's damage front, and the scene is built again around it with the state carried
// over (docs/theory.md#moving-zone).
//
// Contract
//  - band_place(scene): where the band goes now, from the crack of the DEM's bond set "interface"
//    measured now (dem/crack_front.hpp: along the band, eight strips across it). nullopt while
//    the damage front stays `margin` or more behind the band's `to` (or has not started), and
//    once `to` is at `until`; else to = min(front + ahead, until) and from = max(from, tip -
//    behind), from kept where the band would be too short for its two overlaps and a core.
//  - move_zone(first, current, place): the case of `first` (the run's scene as built) built again
//    with the run's options and these overrides: the band's from and to; the interface's `area`
//    scaled by the band's length inside the packing's region (the area per length of the case's
//    band); continuum.mesh.join's box with its lower end along the band moved as `to` moved; and
//    time.dt the run's step (refused, as any case, if above the new scene's critical step). Then
//    `current`'s state is carried over through the models' checkpoint archives:
//      * DEs with the same reference position: their motion (position, velocity, orientation,
//        spin); bonds and cohesive links between two such DEs: broken flags, damage and
//        dissipation, with the break records of those bonds; continuum nodes with the same
//        reference position and side of the band's mid-plane (ContinuumPart::node_sides: a
//        node joined before is both sides' after): displacement and velocity; the running sums
//        (time, step, external works, dissipation, fracture, the coupling's work);
//      * DEs new to the zone: the continuum's motion at their reference position X, the
//        displacement and velocity interpolated there, the orientation the rotation of F = I +
//        du/dX (polar decomposition) and the spin the axial vector of dF/dt F^-1 (central
//        differences over 1e-6 m);
//      * continuum nodes where the DEM's weight alpha_d falls (the zone left them behind), those
//        new to the continuum (of tetrahedra the pure-DEM zone left out before, alpha_d = 1
//        there) and, when `from` moves, those of the DEM-only zone (alpha_d = 1) in the elements
//        the new start overlap reaches (up to the vertex plane at or beyond from + width): first
//        alpha_d u_DEM + (1 - alpha_d) u, alpha_d the weight before and u_DEM the affine field
//        fitted by least squares to the 16 nearest DEs on their side of the mid-plane, at the
//        node (displacement and velocity alike); then their displacement relaxed to the
//        continuum's equilibrium with the other nodes held (the least strain energy: one Newton
//        step by conjugate gradients), and when `from` moves with them every node the coupled
//        DEs' field does not reach (supports and driven strips held). The coupled DEs stay where
//        they are: the coupling keeps the displacement constraint's residual G u as it finds it
//        (SceneModel::displacement_residual: 0 after a move of `to` alone);
//      * then the forces and the coupling's constraint of that state
//        (SceneModel::resume_from_set_state). The crack sensors keep the pre-crack tip of the
//        scene as first built, and the energy dissipated by links left behind;
//      * after a move of `from`, follow.relax_steps of the coupled state's dynamic relaxation
//        (SceneModel::relax) to its equilibrium at the present load: every continuum dof and
//        every DE both scenes have toward rest, the DEs new to the zone toward their own
//        accelerations as set (ZoneMove::relaxation).
//    Only between two steps where current.model->accepts_set_state(). InputError (naming the
//    follow section) where the case cannot move: no interface, a join that is not a box.
//  - The move changes the total energy (DEs and links dropped behind and added ahead, weights
//    moved, the relaxation): ZoneMove::energy_jump, which the run's energy balance books as its
//    own term, less what the relaxation's damage dissipated (booked as fracture). A move of `to`
//    alone changes it by a few 1e-3 of the total or less. A move of `from` hands the DEM's wake to
//    the continuum, the DEM's stress at the new start overlap in one step; without the relaxation
//    the arms then ring, which the settling after it (BandSettling) does not stop
//    (docs/decisions.md#d56).
#pragma once
#include <memory>
#include <optional>

#include "app/scene.hpp"

namespace arlequin::app {

struct BandPlace {
  double from = 0.0, to = 0.0;  // m, along the band
};

struct ZoneMove {
  std::size_t des = 0, des_kept = 0, des_added = 0, des_dropped = 0;
  std::size_t nodes_added = 0;            // continuum nodes of the pure-DEM zone before
  std::size_t nodes_from_des = 0;         // nodes whose motion the DEs gave (those added among them)
  std::size_t links_dropped_broken = 0;  // bonds left behind broken (with their break records)
  double energy_before = 0.0, energy_after = 0.0;  // J, the scene's total energy
  // The change of the total energy the balance books as the move's: all of it but what the
  // relaxation's damage dissipated, which E_fracture books.
  double energy_jump() const { return energy_after - energy_before + relaxation.fracture; }
  double setup_seconds = 0.0;  // building the new scene and carrying the state
  RelaxationReport relaxation;  // after a move of from (follow.relax_steps; steps 0: none)
};

std::optional<BandPlace> band_place(const Scene& scene);

// After a move of the band's start: its DEs from the new start to follow.settle_length beyond it
// kinetically damped over the next follow.settle_time (docs/decisions.md#d56). After each macro
// step, when their kinetic energy fell since the one before, they stop (SceneModel::arrest: their
// kinetic energy goes to the DEM's dissipated energy, the velocities back onto the coupling's
// constraint), as dynamic relaxation stops a structure at its kinetic energy's peaks; the rest
// of both models steps on. A move while it lasts picks the DEs of the moved scene again: start()
// after a move of `from`, carry_to() after another.
class BandSettling {
 public:
  void start(const Scene& moved);     // the moved scene's band from `from`, for settle_time
  void carry_to(const Scene& moved);  // the same steps left, the moved scene's DEs
  bool active() const { return steps_left_ > 0; }
  void after_step(const dem::DemModel& dem, SceneModel& model);  // while active()
  double dissipated() const { return dissipated_; }  // J, since start()
  long steps_done() const { return steps_done_; }
  std::size_t particles() const { return ids_.size(); }

 private:
  void pick(const Scene& moved);
  std::vector<std::uint32_t> ids_;
  long steps_left_ = 0, steps_done_ = 0;
  double last_kinetic_ = 0.0, dissipated_ = 0.0;
};

std::unique_ptr<Scene> move_zone(const Scene& first, Scene& current, BandPlace place, ZoneMove& report);

// build_scene's check of a case whose band follows a crack (InputError at the follow section).
void check_band_follow(const Scene& scene);

}  // namespace arlequin::app
