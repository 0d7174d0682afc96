// The element kernels are specialised by the model's effect set (forces.cpp: one loop per
// combination, chosen once per evaluation). Each must give what a general per-element
// evaluation of the same laws gives, to round-off, for every combination of effects.
#include "block_mesh.h"

#include "liversim/engine/fibres.h"
#include "liversim/engine/forces.h"
#include "liversim/engine/material.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace liversim {
namespace {

// The general kernel: every law looked up per element, nothing specialised, forces scattered
// element by element. `viscous` is the history the evaluation starts from, advanced by dt_s.
NodeArray reference_forces(const SimModel& model, const NodeArray& x, ViscousHistory& viscous,
                           double dt_s) {
  const std::size_t tets = model.tet_count;
  std::vector<double> nodal_pressure(model.node_count, 0.0);
  auto is_viscous = [&](std::size_t e) {
    return model.effects.viscous && model.viscous_parameters[model.region[e]].has_value();
  };
  if (model.effects.average_nodal_pressure)
    for (std::size_t n = 0; n < model.node_count; ++n) {
      double weighted = 0.0, volume = 0.0, lambda_volume = 0.0;
      for (std::size_t e = 0; e < tets; ++e) {
        bool corner = false;
        for (int c = 0; c < 4; ++c) corner |= static_cast<std::size_t>(model.corner[c][e]) == n;
        if (!corner || is_viscous(e)) continue;
        weighted += model.rest_volume_m3[e] * deformation_gradient(model, x, e).determinant();
        volume += model.rest_volume_m3[e];
        lambda_volume += model.rest_volume_m3[e] * model.lame_lambda_pa[e];
      }
      if (volume > 0.0)
        nodal_pressure[n] = neo_hookean::lambda_pressure(weighted / volume, lambda_volume / volume);
    }
  NodeArray force;
  force.resize(model.node_count);
  for (std::size_t e = 0; e < tets; ++e) {
    const Eigen::Matrix3d F = deformation_gradient(model, x, e);
    Eigen::Matrix3d P;
    if (is_viscous(e)) {
      const ViscousTissueStep step(*model.viscous_parameters[model.region[e]], dt_s);
      ViscousTissueState history = viscous.load(e);
      P = viscous_tissue_update(F, step, history);
      viscous.store(e, history);
      if (model.effects.fibres)
        for (const auto& family : model.fibre_direction)
          P += hgo::first_piola_stress(F, family[e], model.fibre_parameters[e]);
    } else if (model.effects.average_nodal_pressure) {
      double pressure = 0.0;
      for (int c = 0; c < 4; ++c) pressure += 0.25 * nodal_pressure[model.corner[c][e]];
      P = neo_hookean::first_piola_stress_given_lambda_pressure(F, model.shear_modulus_pa[e],
                                                                model.lame_lambda_pa[e], pressure);
      if (model.effects.mooney_rivlin)
        P += mooney_rivlin::extra_first_piola_stress(F, model.mooney_rivlin_c2_pa[e]);
      if (model.effects.fibres)
        for (const auto& family : model.fibre_direction)
          P += hgo::first_piola_stress(F, family[e], model.fibre_parameters[e]);
    } else {
      P = element_first_piola_stress(model, e, F);  // Neo-Hookean, Mooney–Rivlin, fibres
    }
    const Eigen::Matrix3d h =
        -model.rest_volume_m3[e] * P * element_dm_inverse(model, e).transpose();
    for (int c = 1; c < 4; ++c) {
      const auto n = model.corner[c][e];
      force.set(n, force.at(n) + h.col(c - 1));
      const auto n0 = model.corner[0][e];
      force.set(n0, force.at(n0) - h.col(c - 1));
    }
  }
  return force;
}

TEST(Kernels, EverySpecialisedKernelEqualsTheGeneralOne) {
  // 480 tets: blocks of the viscous loop with one region and with both, and a partial last one.
  TetMesh mesh = testing::block_mesh(5, 4, 4, {0.03, 0.02, 0.02}, 0.2);
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    double x = 0.0;
    for (int c = 0; c < 4; ++c) x += 0.25 * mesh.rest_position_m.x[mesh.corner[c][e]];
    mesh.region[e] = x > 0.015 ? 1 : 0;
  }
  std::mt19937 random(11);
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  int combinations = 0;
  const std::shared_ptr<WorkerPool> workers = make_worker_pool(2);
  for (int mask = 0; mask < 32; ++mask) {
    const bool fibres = mask & 1, viscous = mask & 2, averaged = mask & 4, mooney = mask & 8;
    // Every region viscous, with different laws: the plain viscous loop (Mooney–Rivlin is not
    // available in a viscous region).
    const bool all_viscous = mask & 16;
    if (all_viscous && (!viscous || mooney)) continue;
    ModelOptions options;
    options.regions.resize(2);
    options.regions[0].tissue = TissueMaterial{3500.0, 0.45, 1060.0};
    options.regions[1].tissue = TissueMaterial{7000.0, 0.49, 1060.0};
    if (mooney) options.regions[0].tissue.mooney_rivlin_fraction = 0.3;
    if (viscous) {
      options.regions[1].viscoelastic = ViscoelasticParameters{4000.0, 3000.0, 400.0};
      options.regions[1].viscoplastic = ViscoplasticParameters{20.0, 500.0, 0.5};
      if (all_viscous)
        options.regions[0].viscoelastic = ViscoelasticParameters{2000.0, 1500.0, 50.0};
    }
    if (fibres) {
      options.regions[0].fibres = FibreParameters{1000.0, 2.0};
      options.regions[1].fibres = FibreParameters{500.0, 5.0};
      options.fibre_field.first_family = {Eigen::Vector3d(1.0, 0.2, 0.0)};
      options.fibre_field.second_family = {Eigen::Vector3d(0.0, 1.0, 0.3)};
    }
    options.average_nodal_pressure = averaged;
    const SimModel model = build_model(mesh, options);
    SimState state = make_rest_state(model);
    // The same evaluation on two threads gives the same numbers, bit for bit (fixed chunks, results
    // combined in chunk order): a replay reproduces a session whatever the machine's cores.
    SimState threaded = make_rest_state(model, workers);
    // Two deformed configurations: the first commits a viscous history (yield passed), the
    // second is compared from it.
    for (int stage = 0; stage < 2; ++stage) {
      for (std::size_t n = 0; n < model.node_count; ++n) {
        const Eigen::Vector3d rest = model.rest_position_m.at(n);
        const Eigen::Vector3d stretch(0.15 * rest.x() * (stage + 1), -0.03 * rest.y(), 0.0);
        const Eigen::Vector3d noise(jitter(random), jitter(random), jitter(random));
        state.position_m.set(n, rest + stretch + 5e-4 * noise);
      }
      // One node pushed through its neighbours: inverted elements (J < J0) in the second stage.
      if (stage == 1)
        state.position_m.set(model.node_count / 2, state.position_m.at(model.node_count / 2) +
                                                       Eigen::Vector3d(0.012, 0.004, 0.0));
      const ViscousHistory before = state.viscous_history;
      threaded.position_m = state.position_m;
      const ElasticEvaluation seen = compute_internal_forces(model, state, 0.01);
      const ElasticEvaluation seen_threaded = compute_internal_forces(model, threaded, 0.01);
      EXPECT_EQ(state.force_n.x, threaded.force_n.x);
      EXPECT_EQ(state.force_n.y, threaded.force_n.y);
      EXPECT_EQ(state.force_n.z, threaded.force_n.z);
      EXPECT_EQ(seen.min_volume_ratio, seen_threaded.min_volume_ratio);
      EXPECT_EQ(seen.max_fibre_modulus_pa, seen_threaded.max_fibre_modulus_pa);
      EXPECT_EQ(state.energy.viscous_dissipated_j, threaded.energy.viscous_dissipated_j);
      if (stage == 0) continue;
      ViscousHistory expected_history = before;
      const NodeArray expected = reference_forces(model, state.position_m, expected_history, 0.01);
      double scale = 0.0, difference = 0.0;
      for (std::size_t n = 0; n < model.node_count; ++n) {
        scale = std::max(scale, expected.at(n).norm());
        difference = std::max(difference, (state.force_n.at(n) - expected.at(n)).norm());
      }
      ASSERT_GT(scale, 0.0);
      // Round-off: the same operations in another order, sums of ~20 element terms per node.
      EXPECT_LE(difference, 1e-12 * scale)
          << "fibres " << fibres << ", viscous " << viscous << ", average nodal pressure "
          << averaged << ", Mooney-Rivlin " << mooney << ", all viscous " << all_viscous;
      ASSERT_EQ(expected_history.size(), state.viscous_history.size());
      for (int k = 0; k < ViscousHistory::kComponents; ++k) {
        double component_scale = 0.0, component_difference = 0.0;
        for (std::size_t e = 0; e < expected_history.size(); ++e) {
          const double value = expected_history.value(k, e);
          component_scale = std::max(component_scale, std::abs(value));
          component_difference =
              std::max(component_difference, std::abs(state.viscous_history.value(k, e) - value));
        }
        EXPECT_LE(component_difference, 1e-12 * component_scale) << "history component " << k;
      }
      if (all_viscous) {
        // Both paths of the plain viscous loop ran: elements it updated, elements it flagged
        // (yielding or inverted) for the general update.
        const auto& flagged = state.force_scratch.needs_general;
        const auto count = std::count(flagged.begin(), flagged.end(), 1);
        EXPECT_GT(count, 0);
        EXPECT_LT(count, static_cast<long>(model.tet_count));
      }
    }
    ++combinations;
  }
  EXPECT_EQ(combinations, 20);
}

// Blocks of the viscous loop whose elements have all kept Fp = I skip the products with Fp⁻¹;
// blocks where one has flowed keep them. Both must give the general law's forces and history,
// for tissue that flowed and has unloaded below the yield limit (updated by the loop itself).
TEST(Kernels, ViscousLoopSkipsThePlasticProductsOnlyInBlocksThatNeverFlowed) {
  // 480 tets in four layers of 120 along z, in blocks of 64: only the top layer (the last blocks,
  // and elements of the layer below that touch a jittered node above 15 mm) is strained.
  const TetMesh mesh = testing::block_mesh(5, 4, 4, {0.03, 0.02, 0.02}, 0.2);
  ModelOptions options;
  options.regions.resize(1);
  options.regions[0].tissue = TissueMaterial{7000.0, 0.45, 1060.0};
  options.regions[0].viscoelastic = ViscoelasticParameters{4000.0, 3000.0, 400.0};
  options.regions[0].viscoplastic = ViscoplasticParameters{20.0, 500.0, 0.5};
  const SimModel model = build_model(mesh, options);
  SimState state = make_rest_state(model);
  const std::size_t blocks =
      (model.tet_count + ViscousHistory::kBlock - 1) / ViscousHistory::kBlock;
  // A shear of the top layer (z above 15 mm), loaded past the yield limit, then half unloaded.
  for (const double shear : {0.3, 0.15}) {
    for (std::size_t n = 0; n < model.node_count; ++n) {
      const Eigen::Vector3d rest = model.rest_position_m.at(n);
      state.position_m.set(
          n, rest + Eigen::Vector3d(shear * std::max(0.0, rest.z() - 0.015), 0.0, 0.0));
    }
    ViscousHistory expected_history = state.viscous_history;
    const NodeArray expected = reference_forces(model, state.position_m, expected_history, 0.01);
    const ViscousHistory before = state.viscous_history;
    compute_internal_forces(model, state, 0.01);
    double scale = 0.0, difference = 0.0;
    for (std::size_t n = 0; n < model.node_count; ++n) {
      scale = std::max(scale, expected.at(n).norm());
      difference = std::max(difference, (state.force_n.at(n) - expected.at(n)).norm());
    }
    ASSERT_GT(scale, 0.0);
    EXPECT_LE(difference, 1e-12 * scale) << "shear " << shear;
    // Round-off relative to each component's largest value (stresses of kPa; Fp⁻¹ of 1).
    for (int k = 0; k < ViscousHistory::kComponents; ++k) {
      double component_scale = 0.0, component_difference = 0.0;
      for (std::size_t e = 0; e < model.tet_count; ++e) {
        const double value = expected_history.value(k, e);
        component_scale = std::max(component_scale, std::abs(value));
        component_difference =
            std::max(component_difference, std::abs(state.viscous_history.value(k, e) - value));
      }
      EXPECT_LE(component_difference, 1e-12 * component_scale)
          << "history component " << k << ", shear " << shear;
    }
    const long plastic_blocks =
        std::count(state.viscous_history.plastic_blocks(),
                   state.viscous_history.plastic_blocks() + blocks, std::uint8_t{1});
    EXPECT_GT(plastic_blocks, 0) << "shear " << shear;
    EXPECT_LT(plastic_blocks, static_cast<long>(blocks)) << "shear " << shear;
    if (shear < 0.3) {
      // The unloading step: flowed elements that the loop itself updated, with their Fp⁻¹.
      long updated_after_flow = 0;
      for (std::size_t e = 0; e < model.tet_count; ++e)
        updated_after_flow += !state.force_scratch.needs_general[e] &&
                              before.inverse_plastic_deformation(e) != Eigen::Matrix3d::Identity();
      EXPECT_GT(updated_after_flow, 0);
    }
  }
}

}  // namespace
}  // namespace liversim
