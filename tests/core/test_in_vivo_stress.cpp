// The in-vivo stress (in_vivo_stress.h): tissue that has borne its weight on its bed does not flow
// under it, what an instrument adds above it still yields, and only scenes with gravity and a
// region that yields pay for it.
#include "block_mesh.h"

#include "liversim/engine/in_vivo_stress.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"
#include "liversim/engine/support.h"
#include "liversim/engine/viscous_tissue.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <vector>

namespace liversim {
namespace {

constexpr double kEarth = 9.81;
constexpr double kSeedYieldLimitPa = 50.0;

// A block 4 × 3 × 2 cm of the seed's viscoplastic parenchyma resting on its support under
// gravity: at its bottom its weight stresses it by about ρ·g·h = 1060 · 9.81 · 0.02 ≈ 208 Pa,
// four times the yield limit.
ModelOptions resting_block_options(const TetMesh& mesh) {
  ModelOptions options;
  options.regions[0].viscoelastic = kSeedViscoelastic;
  options.regions[0].viscoplastic = ViscoplasticParameters{kSeedYieldLimitPa, 2000.0, 0.5};
  options.gravity_m_per_s2 = {0.0, 0.0, -kEarth};
  options.support =
      std::make_shared<const SupportSurface>(support_under(mesh, options.gravity_m_per_s2));
  return options;
}

TetMesh block() {
  return testing::block_mesh(4, 3, 2, {0.04, 0.03, 0.02});
}

double largest_plastic_strain(const SimModel& model, const SimState& state) {
  double largest = 0.0;
  for (std::size_t e = 0; e < model.tet_count; ++e)
    largest = std::max(largest, state.viscous_history.equivalent_plastic_strain(e));
  return largest;
}

TEST(InVivoStress, IsWhatTheWeightStressesEachElementByOnlyWithGravityAndAYieldLimit) {
  const TetMesh mesh = block();
  ModelOptions options = resting_block_options(mesh);
  const SimModel model = build_model(mesh, options);
  ASSERT_EQ(model.in_vivo_stress_pa.size(), model.tet_count);
  const double largest_pa =
      *std::max_element(model.in_vivo_stress_pa.begin(), model.in_vivo_stress_pa.end());
  // Past the yield limit (which is why it is needed), and of the order of ρ·g·h (208 Pa; the
  // settling's overshoot and the bed's edges add to it), not of the modulus (3500 Pa).
  EXPECT_GT(largest_pa, 2.0 * kSeedYieldLimitPa);
  EXPECT_LT(largest_pa, 1000.0);

  ModelOptions without_gravity = options;
  without_gravity.gravity_m_per_s2.setZero();
  without_gravity.support = nullptr;
  EXPECT_TRUE(build_model(mesh, without_gravity).in_vivo_stress_pa.empty());
  ModelOptions without_yield = options;
  without_yield.regions[0].viscoplastic.reset();
  EXPECT_TRUE(build_model(mesh, without_yield).in_vivo_stress_pa.empty());
  // Gravity switched off on a built model takes it away; on again, it is measured again.
  SimModel changed = model;
  set_gravity(changed, Eigen::Vector3d::Zero(), nullptr);
  EXPECT_TRUE(changed.in_vivo_stress_pa.empty());
  set_gravity(changed, model.gravity_m_per_s2, model.support);
  EXPECT_EQ(changed.in_vivo_stress_pa, model.in_vivo_stress_pa);
}

// Resting on its bed for longer than it settled, the block does not flow at all; the same block
// measured from a stress-free state (the raise taken away) flows under its own weight.
TEST(InVivoStress, ATissueThatHasBorneItsWeightDoesNotFlowUnderIt) {
  const TetMesh mesh = block();
  const SimModel model = build_model(mesh, resting_block_options(mesh));
  SimState state = make_rest_state(model);
  advance(model, state, {}, 1.5 * kInVivoSettlingTime_s);
  EXPECT_EQ(largest_plastic_strain(model, state), 0.0);

  SimModel unraised = model;
  unraised.in_vivo_stress_pa.clear();
  SimState flowing = make_rest_state(unraised);
  advance(unraised, flowing, {}, 1.5 * kInVivoSettlingTime_s);
  EXPECT_GT(largest_plastic_strain(unraised, flowing), 1e-3);
}

// A load on the top of the settled block, 0.2 N on each of its top nodes near the middle (some
// kPa under them, well above the in-vivo stress), makes the tissue under it flow.
TEST(InVivoStress, WhatAnInstrumentAddsAboveItStillYields) {
  const TetMesh mesh = block();
  const SimModel model = build_model(mesh, resting_block_options(mesh));
  SimState state = make_rest_state(model);
  advance(model, state, {}, 0.5);
  ASSERT_EQ(largest_plastic_strain(model, state), 0.0);
  std::vector<PointLoad> press;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    const Eigen::Vector3d x = model.rest_position_m.at(n);
    if (x.z() > 0.0199 && std::abs(x.x() - 0.02) < 0.011 && std::abs(x.y() - 0.015) < 0.008)
      press.push_back({static_cast<NodeIndex>(n), {0.0, 0.0, -0.2}});
  }
  ASSERT_FALSE(press.empty());
  StepInputs inputs;
  inputs.point_loads = press;
  advance(model, state, inputs, 0.5);
  EXPECT_GT(largest_plastic_strain(model, state), 1e-3);
}

// One material point: a held shear whose von Mises stress lies between σs and σs + the raise
// flows without the raise and not with it.
TEST(InVivoStress, RaisesTheYieldLimitOfTheLawAtAPoint) {
  const ViscousTissueParameters law{kSeedViscoelastic, 0.49,
                                    ViscoplasticParameters{kSeedYieldLimitPa, 2000.0, 0.5}};
  const ViscousTissueStep step(law, 1e-3);
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(0, 1) = 0.05;  // σ_eq ≈ √3·μ·γ ≈ 102 Pa
  ViscousTissueState raised, plain;
  for (int i = 0; i < 100; ++i) {
    viscous_tissue_update(F, step, raised, 100.0);
    viscous_tissue_update(F, step, plain);
  }
  EXPECT_EQ(raised.equivalent_plastic_strain, 0.0);
  EXPECT_GT(plain.equivalent_plastic_strain, 0.0);
}

}  // namespace
}  // namespace liversim
