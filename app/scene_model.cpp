// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/scene_model.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "app/continuum_part.hpp"
#include "app/scene.hpp"

namespace arlequin::app {
namespace {

// The DEM and the continuum each with its own step: either one alone, or both side by side.
class Uncoupled final : public SceneModel {
 public:
  Uncoupled(dem::DemModel& dem, ContinuumPart* continuum) : dem_(dem), continuum_(continuum) {}
  void step(double dt) override {
    if (dem_.particles.size() > 0) dem_.step(dt);
    if (continuum_) continuum_->step(dt);
  }
  double critical_time_step() const override {
    const double dem = dem_.critical_time_step();
    return continuum_ ? std::min(dem, continuum_->critical_time_step()) : dem;
  }
  SceneEnergies energies() const override {
    if (!continuum_) return {dem_.energies()};
    return {dem_.energies(), continuum_->kinetic_energy(), continuum_->strain_energy(), 0.0, continuum_->dissipated()};
  }
  std::optional<CouplingMonitorValues> monitor() const override { return std::nullopt; }
  void save_state(StateArchive& archive) const override {
    dem_.save_state(archive);
    if (continuum_) continuum_->save_state(archive);
  }
  void load_state(const StateArchive& archive) override {
    dem_.load_state(archive);
    if (continuum_) continuum_->load_state(archive);
  }
  void write_fields(FieldsWriter& fields, const OutputPlan& plan) const override {
    if (continuum_) continuum_->write_fields(fields);
    write_dem_fields(dem_, fields, plan);
  }

 private:
  dem::DemModel& dem_;
  ContinuumPart* continuum_;  // null without a continuum
};

}  // namespace

std::unique_ptr<SceneModel> uncoupled_scene_model(dem::DemModel& dem, ContinuumPart* continuum) {
  return std::make_unique<Uncoupled>(dem, continuum);
}

namespace {

// Per DE, the index of the smallest group that holds it (of two as small, the later defined),
// -1 for none: a yarn before its family, a material before the whole sample, so that ParaView
// colours by the finest grouping a DE has.
std::vector<std::int32_t> most_specific_group(const dem::DemModel& dem) {
  std::vector<std::int32_t> group(dem.particles.size(), -1);
  std::vector<std::size_t> size(dem.particles.size(), SIZE_MAX);
  for (std::size_t g = 0; g < dem.group_names().size(); ++g) {
    const auto& ids = dem.members(int(g));
    for (const std::uint32_t i : ids)
      if (ids.size() <= size[i]) size[i] = ids.size(), group[i] = std::int32_t(g);
  }
  return group;
}

}  // namespace

void write_dem_fields(const dem::DemModel& dem, FieldsWriter& fields, const OutputPlan& plan) {
  const dem::ParticleSet& p = dem.particles;
  if (p.size() == 0) return;
  fields.add_grid("particles", p.position, FieldsWriter::CellKind::Vertex, {});
  std::vector<Vec3> displacement(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) displacement[i] = p.position[i] - p.reference[i];
  fields.add_point_field("particles", "displacement", displacement);
  fields.add_point_field("particles", "velocity", p.velocity);
  fields.add_point_field("particles", "angular_velocity", p.angular_velocity);
  fields.add_point_field("particles", "radius", p.radius);
  fields.add_point_field("particles", "group", most_specific_group(dem));
  if (dem.failure_enabled()) fields.add_point_field("particles", "damage", dem.damage());
  if (!plan.bond_fields || dem.bond_sets().empty()) return;
  std::vector<std::int64_t> lines;
  std::vector<std::int32_t> set_of, broken;
  std::vector<double> damage;  // 0 or 1 (broken), or a cohesive link's softening damage
  // The stretch of the line between the bond's DEs, |x_j - x_i| / |X_j - X_i| - 1 (X the
  // positions at t = 0, where every bond is made at rest): a spring's elongation, its failure
  // measure; for a beam the axial strain of its centre line.
  std::vector<double> strain;
  for (std::size_t s = 0; s < dem.bond_sets().size(); ++s) {
    const dem::BondSet& set = *dem.bond_sets()[s];
    const auto softening = set.damage_values();
    for (std::size_t b = 0; b < set.size(); ++b) {
      lines.push_back(set.first()[b]);
      lines.push_back(set.second()[b]);
      set_of.push_back(static_cast<std::int32_t>(s));
      broken.push_back(set.broken()[b]);
      damage.push_back(softening.empty() ? set.broken()[b] : softening[b]);
      const std::uint32_t i = set.first()[b], j = set.second()[b];
      strain.push_back(norm(p.position[j] - p.position[i]) / norm(p.reference[j] - p.reference[i]) - 1.0);
    }
  }
  fields.add_grid_sharing_points("bonds", "particles", FieldsWriter::CellKind::Line, lines);
  fields.add_cell_field("bonds", "bond_set", set_of);
  fields.add_cell_field("bonds", "broken", broken);
  fields.add_cell_field("bonds", "damage", damage);
  fields.add_cell_field("bonds", "strain", strain);
}

}  // namespace arlequin::app
