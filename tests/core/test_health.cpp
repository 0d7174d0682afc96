// The step guards (issue 5, case 11): a NaN or infinity in the state or in an input is detected,
// the state goes back to the last good one, the problem is reported, and the simulation goes on.
#include "block_mesh.h"

#include "liversim/engine/health.h"
#include "liversim/engine/model_building.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace liversim {
namespace {

struct GuardFixture : ::testing::TestWithParam<IntegratorKind> {
  TetMesh mesh = testing::block_mesh(4, 1, 1, {0.04, 0.01, 0.01});
  SimModel model;
  std::vector<PointLoad> pull;

  void SetUp() override {
    ModelOptions options;
    options.regions[0].tissue = TissueMaterial{3500.0, 0.45, 1060.0};
    options.regions[0].viscoelastic = ViscoelasticParameters{2000.0, 1500.0, 200.0};
    for (std::size_t n = 0; n < mesh.node_count(); ++n)
      if (mesh.rest_position_m.x[n] < 1e-12) options.fixed_nodes.push_back(NodeIndex(n));
    options.integrator.kind = GetParam();
    options.integrator.step_s = is_explicit(GetParam()) ? 0.0 : 1e-3;
    model = build_model(mesh, options);
    pull = {{NodeIndex(mesh.node_count() - 1), Eigen::Vector3d(0.0, 0.01, 0.0)}};
  }
};

TEST_P(GuardFixture, NanWrittenIntoTheStateIsRolledBackAndTheRunGoesOn) {
  SimState state = make_rest_state(model);
  StateCheckpoint checkpoint = make_checkpoint(model);
  for (int i = 0; i < 5; ++i) {
    const GuardedReport report = guarded_advance(model, state, {pull, {}}, 0.01, checkpoint);
    ASSERT_EQ(report.problem, HealthProblem::none);
  }
  const NodeArray good = state.position_m;
  const double good_time = state.time_s;
  SimState twin = state;  // the same run, not corrupted
  StateCheckpoint twin_checkpoint = make_checkpoint(model);
  guarded_advance(model, twin, {pull, {}}, 0.01, twin_checkpoint);

  state.position_m.y[3] = std::numeric_limits<double>::quiet_NaN();  // a corrupted state
  state.velocity_m_per_s.x[5] = std::numeric_limits<double>::infinity();
  const GuardedReport report = guarded_advance(model, state, {pull, {}}, 0.01, checkpoint);
  EXPECT_EQ(report.problem, HealthProblem::non_finite_position);
  EXPECT_GE(report.rollbacks, 1);
  EXPECT_FALSE(report.gave_up);
  // Went back to the last good state, then advanced from it as the uncorrupted run did, up to the
  // restart of the scheme's history (leapfrog's first kick, BDF2's first step): at most about one
  // step of 0.5 ms in the 10 ms interval, 5 % of the motion.
  EXPECT_NEAR(state.time_s, good_time + 0.01, 1e-12);
  EXPECT_EQ(check_health(model, state), HealthProblem::none);
  double motion = 0.0, difference = 0.0;
  for (std::size_t n = 0; n < good.size(); ++n) {
    motion = std::max(motion, (twin.position_m.at(n) - good.at(n)).norm());
    difference = std::max(difference, (state.position_m.at(n) - twin.position_m.at(n)).norm());
  }
  EXPECT_GT(motion, 0.0);
  EXPECT_LE(difference, 0.05 * motion);
}

TEST_P(GuardFixture, NonFiniteInputsAreRejectedNotStepped) {
  SimState state = make_rest_state(model);
  StateCheckpoint checkpoint = make_checkpoint(model);
  std::vector<PointLoad> bad = pull;
  bad[0].force_n.y() = std::numeric_limits<double>::quiet_NaN();
  GuardedReport report = guarded_advance(model, state, {bad, {}}, 0.01, checkpoint);
  EXPECT_TRUE(report.inputs_rejected);
  EXPECT_EQ(report.problem, HealthProblem::non_finite_input);
  EXPECT_EQ(check_health(model, state), HealthProblem::none);
  EXPECT_NEAR(state.time_s, 0.01, 1e-12);

  const std::vector<NodeSpring> bad_spring{
      {NodeIndex(mesh.node_count() - 1),
       Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0.0, 0.0), 100.0, 1.0}};
  report = guarded_advance(model, state, {{}, bad_spring}, 0.01, checkpoint);
  EXPECT_TRUE(report.inputs_rejected);
  EXPECT_EQ(check_health(model, state), HealthProblem::none);
  // Good inputs again: stepped normally.
  report = guarded_advance(model, state, {pull, {}}, 0.01, checkpoint);
  EXPECT_FALSE(report.inputs_rejected);
  EXPECT_EQ(report.problem, HealthProblem::none);
}

TEST_P(GuardFixture, GivingUpLeavesTheLastGoodState) {
  SimState state = make_rest_state(model);  // at rest: healthy under any speed limit
  StateCheckpoint checkpoint = make_checkpoint(model);
  const NodeArray good = state.position_m;
  // A speed limit no motion can meet: every attempt, at ever shorter steps, fails.
  GuardOptions impossible;
  impossible.speed_limit_m_per_s = 1e-12;
  impossible.max_retries = 2;
  const GuardedReport report =
      guarded_advance(model, state, {pull, {}}, 0.01, checkpoint, impossible);
  EXPECT_TRUE(report.gave_up);
  EXPECT_EQ(report.rollbacks, 3);
  EXPECT_EQ(report.problem, HealthProblem::runaway_speed);
  EXPECT_EQ(state.time_s, 0.0);  // not advanced
  for (std::size_t n = 0; n < good.size(); ++n) EXPECT_EQ(state.position_m.at(n), good.at(n));
  EXPECT_EQ(state.integrator.step_scale, 1.0);
  // The next call with sane limits goes on from there.
  EXPECT_EQ(guarded_advance(model, state, {pull, {}}, 0.01, checkpoint).problem,
            HealthProblem::none);
  EXPECT_NEAR(state.time_s, 0.01, 1e-12);
}

// A blow-up is told from fast motion by energy: a node may move as fast as the energy supplied
// allows, not faster. The same velocity is a runaway at rest and healthy once the books hold the
// energy it needs (e.g. a device's full force flinging a light node).
TEST_P(GuardFixture, ANodeWithMoreKineticEnergyThanSuppliedIsARunaway) {
  SimState state = make_rest_state(model);
  const std::size_t node = model.node_count - 1;
  state.velocity_m_per_s.y[node] = 3.0;  // far below the speed limit
  EXPECT_EQ(check_health(model, state), HealthProblem::runaway_energy);
  const double kinetic = 0.5 * model.lumped_mass_kg[node] * 9.0;
  state.energy.tool_work_j = kinetic;  // as if a load had done that much work
  EXPECT_EQ(check_health(model, state), HealthProblem::none);
  state.energy.tool_work_j = kinetic / 1.2;  // beyond the 10 % slack
  EXPECT_EQ(check_health(model, state), HealthProblem::runaway_energy);
  // The guard rolls such a state back.
  StateCheckpoint checkpoint = make_checkpoint(model);
  SimState rest = make_rest_state(model);
  guarded_advance(model, rest, {pull, {}}, 0.01, checkpoint);
  rest.velocity_m_per_s.y[node] =
      1e3 * std::sqrt(2.0 * rest.energy.tool_work_j / model.lumped_mass_kg[node]);
  const GuardedReport report = guarded_advance(model, rest, {pull, {}}, 0.01, checkpoint);
  EXPECT_EQ(report.problem, HealthProblem::runaway_energy);
  EXPECT_GE(report.rollbacks, 1);
  EXPECT_FALSE(report.gave_up);
}

// An implicit step whose Newton iteration stops short is not a solution: it is rolled back and
// retried with shorter steps, and when none converges the state stays the last good one.
// The real-time loop steps one cycle a step at a time while a tool acts, and keeps one checkpoint
// for the cycle (saved before its first step and after its last): a state gone bad in between
// goes back to the cycle's start, not to the step before.
TEST_P(GuardFixture, TheStepsOfOneCycleShareOneCheckpoint) {
  SimState state = make_rest_state(model);
  StateCheckpoint checkpoint = make_checkpoint(model);
  const StepInputs inputs{pull, {}};
  ASSERT_EQ(guarded_advance(model, state, inputs, 0.01, checkpoint).problem, HealthProblem::none);
  const double cycle_start_s = state.time_s;
  const NodeArray cycle_start = state.position_m;
  GuardOptions first, middle, last;
  first.checkpoint_after_advance = false;
  middle.checkpoint_on_entry = middle.checkpoint_after_advance = false;
  last.checkpoint_on_entry = false;
  ASSERT_FALSE(guarded_advance(model, state, inputs, 0.002, checkpoint, first).rollbacks);
  ASSERT_FALSE(guarded_advance(model, state, inputs, 0.002, checkpoint, middle).rollbacks);
  EXPECT_EQ(checkpoint.time_s, cycle_start_s) << "not saved within the cycle";
  EXPECT_NEAR(state.time_s, cycle_start_s + 0.004, 1e-12);
  state.position_m.y[3] = std::numeric_limits<double>::quiet_NaN();
  const GuardedReport report = guarded_advance(model, state, inputs, 0.002, checkpoint, last);
  EXPECT_GE(report.rollbacks, 1);
  EXPECT_FALSE(report.gave_up);
  // Back at the cycle's start and one step on from it; that state is the new checkpoint.
  EXPECT_NEAR(state.time_s, cycle_start_s + 0.002, 1e-12);
  EXPECT_EQ(checkpoint.time_s, state.time_s);
  EXPECT_EQ(check_health(model, state), HealthProblem::none);
  double moved = 0.0;
  for (std::size_t n = 0; n < cycle_start.size(); ++n)
    moved = std::max(moved, (state.position_m.at(n) - cycle_start.at(n)).norm());
  EXPECT_LT(moved, 1e-3) << "one 2 ms step from the cycle's start";
  // With the defaults each good step is saved: the same corruption goes back one step only.
  SimState saved_each = make_rest_state(model);
  StateCheckpoint each = make_checkpoint(model);
  for (int i = 0; i < 3; ++i) guarded_advance(model, saved_each, inputs, 0.002, each);
  saved_each.position_m.y[3] = std::numeric_limits<double>::quiet_NaN();
  guarded_advance(model, saved_each, inputs, 0.002, each);
  EXPECT_NEAR(saved_each.time_s, 0.008, 1e-12);
}

// A caller that saves seldom (the real-time loop: once per 5 ms of simulated time) still moves its
// checkpoint past a failure: an advance that had to roll back saves the good state it reached,
// whatever the options say. Before, each failure went back to the same old checkpoint, the retry
// got no further than the failure, and a live loop went round 23.84 s of a bimanual resection for
// minutes.
TEST_P(GuardFixture, AnAdvanceThatRolledBackSavesWhereItGotToEvenWhenAskedNotTo) {
  SimState state = make_rest_state(model);
  StateCheckpoint checkpoint = make_checkpoint(model);
  const StepInputs inputs{pull, {}};
  ASSERT_EQ(guarded_advance(model, state, inputs, 0.01, checkpoint).problem, HealthProblem::none);
  GuardOptions seldom;
  seldom.checkpoint_on_entry = seldom.checkpoint_after_advance = false;
  ASSERT_FALSE(guarded_advance(model, state, inputs, 0.002, checkpoint, seldom).rollbacks);
  const double saved_s = checkpoint.time_s;
  EXPECT_LT(saved_s, state.time_s) << "a good advance is not saved when asked not to";
  state.position_m.y[3] = std::numeric_limits<double>::quiet_NaN();
  const GuardedReport report = guarded_advance(model, state, inputs, 0.002, checkpoint, seldom);
  ASSERT_GE(report.rollbacks, 1);
  EXPECT_FALSE(report.gave_up);
  EXPECT_NEAR(state.time_s, saved_s + 0.002, 1e-12);
  EXPECT_EQ(checkpoint.time_s, state.time_s) << "the retry's good state was not saved";
}

TEST(Guard, UnconvergedImplicitStepsAreRolledBack) {
  const TetMesh mesh = testing::block_mesh(4, 1, 1, {0.04, 0.01, 0.01});
  ModelOptions options;
  for (std::size_t n = 0; n < mesh.node_count(); ++n)
    if (mesh.rest_position_m.x[n] < 1e-12) options.fixed_nodes.push_back(NodeIndex(n));
  options.integrator.kind = IntegratorKind::backward_euler;
  options.integrator.step_s = 1e-3;
  options.integrator.max_newton_iterations = 1;  // one iteration cannot reach 1e-15 m
  options.integrator.newton_tolerance_m = 1e-15;
  const SimModel model = build_model(mesh, options);
  SimState state = make_rest_state(model);
  StateCheckpoint checkpoint = make_checkpoint(model);
  const std::vector<PointLoad> pull{{NodeIndex(mesh.node_count() - 1), {0.0, 0.05, 0.0}}};
  GuardOptions guard;
  guard.max_retries = 2;
  const GuardedReport report = guarded_advance(model, state, {pull, {}}, 0.004, checkpoint, guard);
  EXPECT_EQ(report.problem, HealthProblem::solver_failed);
  EXPECT_TRUE(report.gave_up);
  EXPECT_EQ(report.rollbacks, 3);
  EXPECT_EQ(state.time_s, 0.0);
}

// A step that has collapsed (here the travel limit of a node thrown so fast that it allows only a
// two-thousandth of the rest step) ends the advance at once rather than holding it for a thousand
// evaluations and more, and the guard takes it as a problem: it retries, then gives up on the
// checkpoint, and says why.
TEST(Guard, AStepFallenBelowAThousandthOfItsRestValueEndsTheAdvanceAndIsAProblem) {
  const TetMesh mesh = testing::block_mesh(4, 1, 1, {0.04, 0.01, 0.01});
  const SimModel model = build_model(mesh, ModelOptions{});
  ASSERT_GT(model.stable_time_step_s, 0.0);
  const double collapsing_speed_m_per_s =
      0.1 * model.min_element_height_m / (0.5 * kCollapsedStepFraction * model.stable_time_step_s);
  SimState state = make_rest_state(model);
  state.velocity_m_per_s.x[0] = state.max_speed_m_per_s = collapsing_speed_m_per_s;
  const StepReport steps = advance(model, state, {}, 10.0 * model.stable_time_step_s);
  EXPECT_TRUE(steps.step_collapsed);
  EXPECT_EQ(steps.substeps, 0);
  EXPECT_EQ(steps.force_evaluations, 1);

  SimState thrown = make_rest_state(model);
  thrown.velocity_m_per_s.x[0] = thrown.max_speed_m_per_s = collapsing_speed_m_per_s;
  StateCheckpoint checkpoint = make_checkpoint(model);
  GuardOptions guard;
  guard.kinetic_energy_slack = 1e12;  // the energy check and the speed backstop would flag the
  guard.speed_limit_m_per_s = 1e12;   // throw itself
  const GuardedReport report =
      guarded_advance(model, thrown, {}, 10.0 * model.stable_time_step_s, checkpoint, guard);
  EXPECT_EQ(report.problem, HealthProblem::step_collapsed);
  EXPECT_TRUE(report.gave_up);
  EXPECT_EQ(report.rollbacks, guard.max_retries + 1);
  EXPECT_EQ(thrown.time_s, 0.0);
  EXPECT_NE(health_problem_text(report.problem).find("step fell below"), std::string_view::npos);
}

INSTANTIATE_TEST_SUITE_P(Integrators, GuardFixture, ::testing::ValuesIn(kAllIntegrators),
                         [](const auto& info) {
                           std::string name(integrator_name(info.param));
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

}  // namespace
}  // namespace liversim
