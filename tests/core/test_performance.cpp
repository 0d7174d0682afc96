// The measures behind liversim-cli bench (core/performance.h). Timing is never asserted; memory
// accounting is: state for an effect exists only when the effect is on.
#include "block_mesh.h"

#include "liversim/engine/model_building.h"
#include "liversim/studies/performance.h"

#include <gtest/gtest.h>

#include <cmath>

namespace liversim {
namespace {

TEST(Performance, StateForAnEffectIsHeldOnlyWhenItIsOn) {
  const TetMesh mesh = testing::block_mesh(4, 2, 2, {0.04, 0.02, 0.02});
  ModelOptions elastic;
  const SimModel plain = build_model(mesh, elastic);
  ModelOptions viscous = elastic;
  viscous.regions[0].viscoelastic = kSeedViscoelastic;
  const SimModel with_arm = build_model(mesh, viscous);
  ModelOptions fibres = elastic;
  fibres.regions[0].fibres = FibreParameters{1000.0, 2.0};
  fibres.fibre_field.first_family = {Eigen::Vector3d::UnitX()};
  const SimModel with_fibres = build_model(mesh, fibres);

  const std::size_t plain_state = state_bytes(make_rest_state(plain));
  // The viscous history is 23 doubles and more per element; fibres add per-element directions.
  EXPECT_GE(state_bytes(make_rest_state(with_arm)),
            plain_state + mesh.tet_count() * ViscousHistory::kComponents * sizeof(double));
  EXPECT_EQ(state_bytes(make_rest_state(with_fibres)), plain_state);
  EXPECT_GE(model_bytes(with_fibres),
            model_bytes(plain) + mesh.tet_count() * (sizeof(FibreParameters) + 3 * sizeof(double)));
  // A model holds at least its Dm⁻¹ (9 doubles per element) and positions (3 per node).
  EXPECT_GE(model_bytes(plain),
            mesh.tet_count() * 9 * sizeof(double) + mesh.node_count() * 3 * sizeof(double));
}

TEST(Performance, TheTimersCountWhatTheyRan) {
  const TetMesh mesh = testing::block_mesh(2, 1, 1, {0.02, 0.01, 0.01});
  const SimModel model = build_model(mesh, {});
  SimState state = make_rest_state(model);
  const ForceEvaluationTiming forces = time_force_evaluations(model, state, 1e-3, 1e-3, 2);
  EXPECT_GE(forces.evaluations, 1);
  EXPECT_GT(forces.ns_per_tet, 0.0);
  const SteppingTiming steps = time_stepping(model, state, {}, 1e-3, 1e-3);
  EXPECT_GE(steps.simulated_s, 1e-3);
  EXPECT_GE(steps.steps.substeps, 1);
  EXPECT_NEAR(state.time_s, steps.simulated_s, 1e-12);
}

TEST(Performance, AScenesCostIsMeasuredOnItsOwnModelInWholeMillisecondIntervals) {
  SceneSetup scene = default_scene(1000);
  const SteppingTiming timing = time_scene_under_pull(scene, 1e-3);
  // Whole 1 ms intervals; the explicit step is below 1 ms, so each takes at least one substep.
  EXPECT_GE(timing.simulated_s, 1e-3);
  EXPECT_NEAR(timing.simulated_s / 1e-3, std::round(timing.simulated_s / 1e-3), 1e-9);
  EXPECT_GE(timing.steps.substeps, std::lround(timing.simulated_s / 1e-3));
  EXPECT_GT(timing.steps_per_s(), 0.0);
  // A model that cannot be built is reported as build_model reports it.
  scene.model_options.regions[0].tissue.poisson_ratio = 0.7;
  EXPECT_THROW(time_scene_under_pull(scene, 1e-3), std::invalid_argument);
}

}  // namespace
}  // namespace liversim
