#include "liversim/core/model.h"

#include "liversim/core/integrator.h"
#include "liversim/core/mesh_quality.h"

#include <Eigen/Dense>

#include <cmath>
#include <stdexcept>
#include <string>

namespace liversim {
namespace {

void build_incidence(SimModel& model) {
  const std::size_t tets = model.tet_count;
  model.node_slot_begin.assign(model.node_count + 1, 0);
  for (int c = 0; c < 4; ++c)
    for (std::size_t e = 0; e < tets; ++e) ++model.node_slot_begin[model.corner[c][e] + 1];
  for (std::size_t n = 0; n < model.node_count; ++n)
    model.node_slot_begin[n + 1] += model.node_slot_begin[n];
  model.node_slots.resize(4 * tets);
  std::vector<std::int32_t> fill(model.node_slot_begin.begin(), model.node_slot_begin.end() - 1);
  for (int c = 0; c < 4; ++c)
    for (std::size_t e = 0; e < tets; ++e)
      model.node_slots[fill[model.corner[c][e]]++] = static_cast<std::int32_t>(c * tets + e);
}

}  // namespace

SimModel build_model(const TetMesh& mesh, const ModelOptions& options) {
  if (auto problem = validate(options.material)) throw std::invalid_argument(*problem);
  if (mesh.tet_count() == 0) throw std::invalid_argument("the mesh has no tetrahedra");
  if (!(options.mass_damping_per_s >= 0.0) || !std::isfinite(options.mass_damping_per_s))
    throw std::invalid_argument("mass damping must be a finite value >= 0 (1/s)");
  if (!(options.stable_step_safety > 0.0 && options.stable_step_safety <= 1.0))
    throw std::invalid_argument("stable step safety factor must be in (0, 1]");

  SimModel model;
  model.node_count = mesh.node_count();
  model.tet_count = mesh.tet_count();
  model.corner = mesh.corner;
  model.rest_position_m = mesh.rest_position_m;
  model.material = options.material;
  model.mass_damping_per_s = options.mass_damping_per_s;
  model.stable_step_safety = options.stable_step_safety;

  const std::size_t tets = model.tet_count;
  for (auto& entry : model.dm_inverse) entry.resize(tets);
  model.rest_volume_m3.resize(tets);
  model.shear_modulus_pa.assign(tets, options.material.shear_modulus_pa());
  model.lame_lambda_pa.assign(tets, options.material.lame_lambda_pa());
  model.lumped_mass_kg.assign(model.node_count, 0.0);

  for (std::size_t e = 0; e < tets; ++e) {
    const auto nodes = mesh.tet(e);
    for (auto n : nodes) {
      if (n < 0 || static_cast<std::size_t>(n) >= model.node_count)
        throw std::invalid_argument("element " + std::to_string(e) + " refers to node " +
                                    std::to_string(n) + ", outside the mesh");
    }
    const Eigen::Vector3d x0 = mesh.rest_position_m.at(nodes[0]);
    Eigen::Matrix3d dm;
    for (int c = 1; c < 4; ++c) dm.col(c - 1) = mesh.rest_position_m.at(nodes[c]) - x0;
    const double volume = dm.determinant() / 6.0;
    const double scale = dm.colwise().norm().maxCoeff();
    if (!(volume > 1e-12 * scale * scale * scale))
      throw std::invalid_argument("element " + std::to_string(e) +
                                  (volume < 0 ? " is inverted" : " has zero volume") +
                                  " in the rest configuration");
    const Eigen::Matrix3d inv = dm.inverse();
    for (int k = 0; k < 9; ++k) model.dm_inverse[k][e] = inv(k / 3, k % 3);
    model.rest_volume_m3[e] = volume;
    const double corner_mass = options.material.density_kg_per_m3 * volume / 4.0;
    for (auto n : nodes) model.lumped_mass_kg[n] += corner_mass;
  }

  model.is_fixed.assign(model.node_count, 0);
  for (auto n : options.fixed_nodes) {
    if (n < 0 || static_cast<std::size_t>(n) >= model.node_count)
      throw std::invalid_argument("fixed node " + std::to_string(n) + " is outside the mesh (" +
                                  std::to_string(model.node_count) + " nodes)");
    model.is_fixed[n] = 1;
  }
  model.inverse_mass_per_kg.resize(model.node_count);
  for (std::size_t n = 0; n < model.node_count; ++n) {
    // A node no element touches has no mass; keep it still rather than divide by zero.
    const bool free = !model.is_fixed[n] && model.lumped_mass_kg[n] > 0.0;
    model.inverse_mass_per_kg[n] = free ? 1.0 / model.lumped_mass_kg[n] : 0.0;
  }

  model.min_element_height_m = assess_quality(mesh).min_height_m;
  build_incidence(model);
  model.max_frequency_rad_per_s = estimate_max_frequency_rad_per_s(model, model.rest_position_m);
  model.stable_time_step_s = stable_time_step_s(model, StepInputs{});
  return model;
}

}  // namespace liversim
