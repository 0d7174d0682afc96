// The real-time loop's fixed-step clock: wall time in, whole steps out, at most a cap per cycle,
// and the backlog beyond the cap dropped (simulated time slows down instead of spiralling). The
// clock is tested with made-up elapsed times; the running loop only for what a tiny cap on a
// heavy model must give whatever the machine's speed.
#include "block_mesh.h"

#include "liversim/engine/integrator.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/surface.h"
#include "liversim/haptics/emulated_devices.h"
#include "liversim/interaction/cutting.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/meshing/liver_geometry.h"
#include "liversim/simulation/realtime_simulation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <span>
#include <stdexcept>
#include <thread>

namespace liversim {
namespace {

constexpr double kStepS = 1e-3;

TEST(StepAccumulator, TakesOnlyWholeStepsAndKeepsTheFractionForLater) {
  StepAccumulator clock(kStepS, 100);
  EXPECT_EQ(clock.add(0.4e-3).steps, 0);
  EXPECT_EQ(clock.add(0.4e-3).steps, 0);
  const StepAccumulator::Due due = clock.add(0.4e-3);  // 1.2 steps in all
  EXPECT_EQ(due.steps, 1);
  EXPECT_FALSE(due.capped);
  EXPECT_NEAR(clock.backlog_s(), 0.2e-3, 1e-15);
  EXPECT_NEAR(clock.time_to_next_step_s(), 0.8e-3, 1e-15);
  EXPECT_EQ(clock.add(3.5e-3).steps, 3);  // 3.7 steps: 3 now, 0.7 kept
  EXPECT_NEAR(clock.backlog_s(), 0.7e-3, 1e-15);
}

TEST(StepAccumulator, WallTimesThatSumToWholeStepsGiveThemAll) {
  // 0.1 is not exact in binary: ten of them fall short of 1.0 by an ulp without the slack.
  StepAccumulator clock(0.1, 1000);
  int steps = 0;
  for (int i = 0; i < 10; ++i) steps += clock.add(0.01).steps;
  EXPECT_EQ(steps, 1);
  for (int i = 0; i < 1000; ++i) steps += clock.add(0.1).steps;
  EXPECT_EQ(steps, 1001);
  EXPECT_LT(clock.backlog_s(), 1e-9);
}

TEST(StepAccumulator, TheCapDropsTheBacklogBeyondItAndSaysSo) {
  StepAccumulator clock(kStepS, 4);
  const StepAccumulator::Due due = clock.add(10.3e-3);
  EXPECT_EQ(due.steps, 4);
  EXPECT_TRUE(due.capped);
  EXPECT_NEAR(due.dropped_s, 6e-3, 1e-12);
  // Only the fraction of a step is kept: the next cycle does not start with a backlog to catch up.
  EXPECT_NEAR(clock.backlog_s(), 0.3e-3, 1e-12);
  const StepAccumulator::Due next = clock.add(0.8e-3);
  EXPECT_EQ(next.steps, 1);
  EXPECT_FALSE(next.capped);
  EXPECT_EQ(next.dropped_s, 0.0);
  // Exactly the cap is not "behind".
  StepAccumulator exact(kStepS, 4);
  const StepAccumulator::Due four = exact.add(4e-3);
  EXPECT_EQ(four.steps, 4);
  EXPECT_FALSE(four.capped);
}

TEST(StepAccumulator, AHeavyStepSlowsSimulatedTimeDownInsteadOfSpiralling) {
  // A loop where every step costs three times its own length in wall time: uncapped, each cycle
  // would owe three times more steps than the last. With a cap every cycle takes the cap's steps
  // and simulated time runs at a third of the wall clock's pace.
  constexpr int kCap = 5;
  StepAccumulator clock(kStepS, kCap);
  double elapsed_s = kStepS;  // the first cycle starts one step late
  double simulated_s = 0.0, wall_s = 0.0, dropped_s = 0.0;
  int largest_cycle = 0;
  for (int cycle = 0; cycle < 200; ++cycle) {
    const StepAccumulator::Due due = clock.add(elapsed_s);
    wall_s += elapsed_s;
    simulated_s += due.steps * kStepS;
    dropped_s += due.dropped_s;
    largest_cycle = std::max(largest_cycle, due.steps);
    elapsed_s = 3.0 * kStepS * due.steps;  // the next cycle starts when this one is done
  }
  EXPECT_EQ(largest_cycle, kCap);
  // Every second of wall time is simulated, dropped or still in the backlog.
  EXPECT_NEAR(simulated_s + dropped_s + clock.backlog_s(), wall_s, 1e-9);
  // After the first cycles the loop settles at cap steps per 3 × cap steps of wall time.
  EXPECT_NEAR(simulated_s / wall_s, 1.0 / 3.0, 0.02);
}

TEST(StepAccumulator, IgnoresElapsedTimesThatAreNotTimeAndRejectsABadStepOrCap) {
  StepAccumulator clock(kStepS, 10);
  EXPECT_EQ(clock.add(-1.0).steps, 0);
  EXPECT_EQ(clock.add(std::nan("")).steps, 0);
  EXPECT_EQ(clock.add(std::numeric_limits<double>::infinity()).steps, 0);
  EXPECT_EQ(clock.backlog_s(), 0.0);
  EXPECT_THROW(StepAccumulator(0.0, 10), std::invalid_argument);
  EXPECT_THROW(StepAccumulator(-1e-3, 10), std::invalid_argument);
  EXPECT_THROW(StepAccumulator(std::nan(""), 10), std::invalid_argument);
  EXPECT_THROW(StepAccumulator(kStepS, 0), std::invalid_argument);
}

struct RealtimeSteppingFixture : ::testing::Test {
  static void SetUpTestSuite() { mesh_ = new TetMesh(generate_liver_mesh(1500).mesh); }
  static void TearDownTestSuite() {
    delete mesh_;
    mesh_ = nullptr;
  }
  static std::shared_ptr<const SimModel> model_with(IntegratorSettings integrator) {
    ModelOptions options;
    options.fixed_nodes = mesh_->node_sets.at("ligament");
    options.integrator = integrator;
    return std::make_shared<const SimModel>(build_model(*mesh_, options));
  }
  static Eigen::AlignedBox3d rest_box(const SimModel& model) {
    Eigen::AlignedBox3d box;
    for (std::size_t n = 0; n < model.node_count; ++n) box.extend(model.rest_position_m.at(n));
    return box;
  }
  // The highest and lowest rest heights of the nodes within 8 mm (in x–y) of `where`.
  struct Column {
    double top_m = -std::numeric_limits<double>::infinity();
    double bottom_m = std::numeric_limits<double>::infinity();
  };
  static Column column_at(const SimModel& model, const Eigen::Vector2d& where) {
    Column column;
    for (std::size_t n = 0; n < model.node_count; ++n) {
      const Eigen::Vector3d p = model.rest_position_m.at(n);
      if ((p.head<2>() - where).norm() >= 0.008) continue;
      column.top_m = std::max(column.top_m, p.z());
      column.bottom_m = std::min(column.bottom_m, p.z());
    }
    return column;
  }
  static TetMesh* mesh_;
};
TetMesh* RealtimeSteppingFixture::mesh_ = nullptr;

TEST_F(RealtimeSteppingFixture, TheFixedStepIsTheIntegratorStepOrElseJustUnderTheStableStep) {
  const auto stable = model_with({});
  EXPECT_EQ(realtime_step_s(*stable), kLoopStepFraction * stable->stable_time_step_s);
  const RealtimeSimulation by_cycle(stable, make_rest_state(*stable));
  EXPECT_EQ(by_cycle.step_s(), kLoopStepFraction * stable->stable_time_step_s);
  // The default cap covers two display frames (2/60 s) of simulated time.
  EXPECT_EQ(by_cycle.max_steps_per_cycle(),
            static_cast<int>(std::ceil((2.0 / 60.0) / by_cycle.step_s())));

  IntegratorSettings implicit;
  implicit.kind = IntegratorKind::backward_euler;
  implicit.step_s = 0.04;  // longer than a cycle: still one step at a time
  const auto slow = model_with(implicit);
  EXPECT_EQ(realtime_step_s(*slow), 0.04);
  const RealtimeSimulation one_step(slow, make_rest_state(*slow));
  EXPECT_EQ(one_step.max_steps_per_cycle(), 1);
  EXPECT_EQ(one_step.stats().integrator_name, "backward-euler");
  EXPECT_EQ(one_step.stats().requested_step_s, 0.04);

  RealtimeSimulation::Options options;
  options.max_steps_per_cycle = 7;
  const RealtimeSimulation capped(stable, make_rest_state(*stable), options);
  EXPECT_EQ(capped.max_steps_per_cycle(), 7);
}

// A cycle whose steps have fallen far under its loop step (here a block so stiff that its stable
// step is ~10 ns, under a loop step of 0.1 s: ten million force evaluations, seconds of work) would
// hold stop() for as long as it runs; stop() gives it up after kGiveUpCycleAfterS, where its step
// under way ends. Whole, the cycle would end at 0.1 s of simulated time.
TEST(GiveUpCycle, StopEndsACycleThatWouldRunForSeconds) {
  ModelOptions options;
  options.regions[0].tissue = TissueMaterial{1e14, 0.3, 1000.0};
  const TetMesh mesh = testing::block_mesh(2, 2, 2, {0.01, 0.01, 0.01});
  const auto model = std::make_shared<const SimModel>(build_model(mesh, options));
  ASSERT_LT(model->stable_time_step_s, 1e-7);
  RealtimeSimulation::Options loop;
  loop.loop_step_s = 0.1;
  loop.max_steps_per_cycle = 1;
  RealtimeSimulation simulation(model, make_rest_state(*model), loop);
  simulation.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the first cycle is due at 0.1 s
  simulation.stop();
  EXPECT_LT(simulation.state().time_s, 0.1 - 1e-9);
}

TEST_F(RealtimeSteppingFixture, ATinyCapOnAHeavyModelReportsBehindAndKeepsWholeSteps) {
  // A step of 0.1 µs, one per cycle: a force evaluation of 1500 elements takes far longer than the
  // step on any machine, so every cycle owes more than the cap and drops the rest.
  IntegratorSettings tiny;
  tiny.step_s = 1e-7;
  const auto model = model_with(tiny);
  RealtimeSimulation::Options options;
  options.max_steps_per_cycle = 1;
  RealtimeSimulation simulation(model, make_rest_state(*model), options);
  simulation.start();
  bool behind = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!behind && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    behind = simulation.stats().behind;
  }
  simulation.stop();
  ASSERT_TRUE(behind) << "the loop never reported falling behind";

  const RealtimeStats stats = simulation.stats();
  EXPECT_EQ(stats.integrator_name, "central-difference");
  EXPECT_EQ(stats.requested_step_s, 1e-7);
  EXPECT_GT(stats.dropped_s, 0.0);
  EXPECT_GT(stats.steps_per_second, 0.0);
  EXPECT_GT(stats.wall_s_per_simulated_s, 0.0);
  // At least one force evaluation per step taken.
  EXPECT_GE(stats.force_evaluations_per_simulated_s, 0.99 / 1e-7);
  // One step per cycle, and every cycle a whole step: simulated time is a whole number of steps.
  const SimState& state = simulation.state();
  ASSERT_GT(state.step_count, 0u);
  const double steps = state.time_s / 1e-7;
  EXPECT_NEAR(steps, std::round(steps), 1e-3) << state.time_s << " s";
}

// A device that sends a NaN (issue 5, case 11): the loop refuses the input, keeps the liver finite
// and goes on stepping; it does not halt.
TEST_F(RealtimeSteppingFixture, ANanFromTheToolIsRefusedAndTheLoopGoesOn) {
  const auto model = model_with({});
  RealtimeSimulation simulation(model, make_rest_state(*model));
  const NodeIndex node = static_cast<NodeIndex>(mesh_->node_count() / 2);
  const NodeSpring bad{node, Eigen::Vector3d(std::nan(""), 0.0, 0.0), 50.0, 0.1};
  simulation.set_springs(std::span<const NodeSpring>(&bad, 1));
  simulation.start();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (simulation.stats().rejected_inputs == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  // Snapshots, not the state: the state is the simulation thread's while it runs.
  auto published_steps = [&] {
    simulation.update_snapshot();
    return simulation.snapshot().step_count;
  };
  const std::uint64_t steps_when_refused = published_steps();
  while (published_steps() <= steps_when_refused && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  simulation.stop();
  const RealtimeStats stats = simulation.stats();
  EXPECT_GT(stats.rejected_inputs, 0);
  EXPECT_EQ(stats.last_problem, HealthProblem::non_finite_input);
  EXPECT_FALSE(stats.halted);
  EXPECT_GT(simulation.state().step_count, steps_when_refused);  // still stepping
  EXPECT_EQ(check_health(*model, simulation.state()), HealthProblem::none);
}

// The loop closes the energy books once per statistics window: a spring pulling the liver
// supplies energy, damping takes some out, and a stable scheme creates none.
TEST_F(RealtimeSteppingFixture, TheLoopKeepsTheEnergyBooks) {
  const auto model = model_with({});
  RealtimeSimulation simulation(model, make_rest_state(*model));
  const NodeIndex node = anterior_marked_node(*mesh_);
  const NodeSpring pull{node, model->rest_position_m.at(node) + Eigen::Vector3d(0.0, 0.0, 0.01),
                        50.0, 0.0};
  simulation.set_springs(std::span<const NodeSpring>(&pull, 1));
  simulation.start();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (simulation.stats().dissipated_fraction <= 0.0 &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  simulation.stop();
  const RealtimeStats stats = simulation.stats();
  EXPECT_FALSE(stats.energy_created);
  EXPECT_GT(stats.dissipated_fraction, 0.0) << "damping takes energy out";
  EXPECT_LE(stats.dissipated_fraction, 1.0) << "no more than was supplied";
}

// A tool in the running loop (issue 7): forceps closed on the anterior surface and lifted 1 cm
// hold the tissue; the published force on them points back down (the tissue pulls back), and the
// held point follows the forceps up. Opened, they let go and feel nothing.
TEST_F(RealtimeSteppingFixture, ForcepsInTheLoopHoldPullAndRelease) {
  const auto model = model_with({});
  RealtimeSimulation simulation(model, make_rest_state(*model));
  simulation.enable_tools(extract_surface(*mesh_));
  ASSERT_TRUE(simulation.tools_enabled());
  const NodeIndex node = anterior_marked_node(*mesh_);
  const Eigen::Vector3d marked = model->rest_position_m.at(node);
  Tool forceps;
  forceps.kind = ToolKind::forceps;
  forceps.jaw_opening = 0.0;
  // Shaft along +z, the anterior normal there; the grasp point on the marked node.
  forceps.pose.origin_m = marked - (forceps_grasp_point_m(forceps) - forceps.pose.origin_m);
  simulation.set_tool(forceps);
  simulation.start();
  auto newest = [&] {
    simulation.update_snapshot();
    return simulation.snapshot();
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!newest().hand(Hand::right).grasping && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_TRUE(newest().hand(Hand::right).grasping)
      << "the forceps closed on the surface took no hold";
  forceps.pose.origin_m.z() += 0.01;
  simulation.set_tool(forceps);
  // Until the held point has come up by half the lift (a second of simulated time at most).
  SimulationSnapshot seen = newest();
  const double start_s = seen.time_s;
  while (seen.position_m.z[node] - marked.z() < 0.005 && seen.time_s < start_s + 1.0 &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    seen = newest();
  }
  EXPECT_GT(seen.position_m.z[node] - marked.z(), 0.005);
  EXPECT_LT(seen.hand(Hand::right).force_n.z(), 0.0) << "the tissue pulls the forceps back down";
  // A device that sends a NaN pose while holding: the step refuses the input, the loop goes on.
  Tool broken = forceps;
  broken.pose.origin_m.x() = std::nan("");
  simulation.set_tool(broken);
  while (simulation.stats().rejected_inputs == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_GT(simulation.stats().rejected_inputs, 0);
  EXPECT_FALSE(simulation.stats().halted);
  EXPECT_THROW(simulation.enable_tools(extract_surface(*mesh_)), std::logic_error)
      << "tools are enabled while the simulation is stopped";
  forceps.jaw_opening = 1.0;
  simulation.set_tool(forceps);
  while (newest().hand(Hand::right).grasping && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  simulation.stop();
  EXPECT_FALSE(simulation.snapshot().hand(Hand::right).grasping);
  EXPECT_EQ(check_health(*model, simulation.state()), HealthProblem::none);
}

// The scalpel in the running loop (issue 7): drawn along the liver with its blade in the
// tissue, it cuts; the published snapshot carries the cut model (more nodes: copies along the
// cut) with positions to match, and the simulation goes on healthy.
TEST_F(RealtimeSteppingFixture, AScalpelDrawnThroughTheLiverCutsItWhileItRuns) {
  const auto model = model_with({});
  RealtimeSimulation simulation(model, make_rest_state(*model));
  EXPECT_THROW(simulation.enable_cutting(), std::logic_error) << "tools come first";
  simulation.enable_tools(extract_surface(*mesh_));
  CuttingSettings anything;
  anything.cutting_stress_pa = 0.0;
  simulation.enable_cutting(anything);
  const Eigen::AlignedBox3d box = rest_box(*model);
  // Blade pointing down (the tool's −z) from 5 mm above the top, 6 cm long.
  Tool scalpel;
  scalpel.kind = ToolKind::scalpel;
  scalpel.geometry.blade_length_m = 0.06;
  const Eigen::Vector3d start(box.center().x() - 0.04, box.center().y(), box.max().z() + 0.005);
  scalpel.pose.origin_m = start;
  simulation.set_tool(scalpel);
  simulation.start();
  EXPECT_THROW(simulation.enable_cutting(), std::logic_error) << "only while stopped";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  SimulationSnapshot seen;
  for (int k = 0; k <= 80 && std::chrono::steady_clock::now() < deadline; ++k) {
    scalpel.pose.origin_m = start + Eigen::Vector3d(0.001 * k, 0.0, 0.0);
    simulation.set_tool(scalpel);
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    simulation.update_snapshot();
    seen = simulation.snapshot();
  }
  simulation.set_tool(std::nullopt);
  simulation.stop();
  ASSERT_TRUE(seen.model);
  EXPECT_GT(seen.topology_version, 0u) << "the stroke cut nothing";
  EXPECT_GT(seen.model->node_count, model->node_count) << "no node copies along the cut";
  EXPECT_EQ(seen.position_m.size(), seen.model->node_count);
  EXPECT_FALSE(simulation.stats().halted);
  EXPECT_EQ(check_health(*seen.model, simulation.state()), HealthProblem::none);
}

// Waits (at most a minute of wall time) until the running simulation has simulated `duration_s`
// more, or `done` holds; returns the last snapshot.
template <class Done>
SimulationSnapshot run_until(RealtimeSimulation& simulation, double duration_s, Done done) {
  simulation.update_snapshot();
  const double until_s = simulation.snapshot().time_s + duration_s;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    simulation.update_snapshot();
    const SimulationSnapshot& seen = simulation.snapshot();
    if (seen.time_s >= until_s || done(seen)) break;
  }
  return simulation.snapshot();
}

// Determinism (issue 10): what the running loop took (tools set from another thread at whatever
// moments, as many steps per cycle as the wall clock gave, the springs of a grab, the cuts the
// scalpel made) replayed in order on the same model from the same state gives the same liver to
// the last bit; a log missing one cycle does not.
TEST_F(RealtimeSteppingFixture, ReplayingTheLoggedInputsReproducesTheRunToTheLastBit) {
  const auto model = model_with({});
  auto make = [&] {
    auto simulation = std::make_unique<RealtimeSimulation>(model, make_rest_state(*model));
    simulation->enable_tools(extract_surface(*mesh_));
    CuttingSettings anything;
    anything.cutting_stress_pa = 0.0;
    simulation->enable_cutting(anything);
    return simulation;
  };
  const auto live = make();
  live->log_inputs(true);
  live->start();
  // Waits for simulated, not wall time: a slow build (a sanitizer's) takes as many cycles.
  const auto simulate_for = [&](double duration_s) {
    run_until(*live, duration_s, [](const SimulationSnapshot&) { return false; });
  };
  // A grab of the marked node pulled 5 mm out and let go, then a probe pressing the top, then
  // the scalpel drawn 6 cm through the liver.
  const NodeIndex node = anterior_marked_node(*mesh_);
  const Eigen::Vector3d marked = model->rest_position_m.at(node);
  const NodeSpring grab{node, marked + Eigen::Vector3d(0.0, 0.0, 0.005), 50.0};
  live->set_springs(std::span(&grab, 1));
  simulate_for(0.150);
  live->clear_springs();
  const Eigen::AlignedBox3d box = rest_box(*model);
  Tool probe;
  probe.pose.origin_m = Eigen::Vector3d(box.center().x(), box.center().y(), box.max().z());
  for (int k = 0; k < 10; ++k) {
    probe.pose.origin_m.z() -= 0.0005;
    live->set_tool(probe);
    simulate_for(0.015);
  }
  Tool scalpel;
  scalpel.kind = ToolKind::scalpel;
  scalpel.geometry.blade_length_m = 0.06;
  const Eigen::Vector3d start(box.center().x() - 0.04, box.center().y(), box.max().z() + 0.005);
  // The left hand's probe presses the top beside the stroke while the scalpel cuts.
  probe.pose.origin_m = Eigen::Vector3d(box.center().x(), box.center().y() + 0.02, box.max().z());
  for (int k = 0; k <= 60; ++k) {
    scalpel.pose.origin_m = start + Eigen::Vector3d(0.001 * k, 0.0, 0.0);
    live->set_tool(scalpel);
    if (k % 6 == 0) {
      probe.pose.origin_m.z() -= 0.0005;
      live->set_tool(Hand::left, probe);
    }
    simulate_for(0.020);
  }
  live->set_tool(std::nullopt);
  live->set_tool(Hand::left, std::nullopt);
  simulate_for(0.050);
  live->stop();
  const std::vector<SimulationInput> log = live->take_input_log();
  int cycles = 0, tools = 0, left_tools = 0, springs = 0;
  for (const SimulationInput& input : log) {
    cycles += input.kind == SimulationInput::Kind::cycle;
    tools += input.kind == SimulationInput::Kind::tool;
    left_tools += input.kind == SimulationInput::Kind::tool && input.hand == Hand::left;
    springs += input.kind == SimulationInput::Kind::springs;
  }
  // A cycle covers at most two display frames: 1.57 s simulated is at least 47 cycles.
  EXPECT_GE(cycles, 47);
  EXPECT_GT(tools, 10);
  EXPECT_EQ(left_tools, 12);  // eleven presses and the probe taken away
  EXPECT_EQ(springs, 2);      // the grab and its release
  ASSERT_GT(live->model().node_count, model->node_count) << "the scalpel cut nothing";
  ASSERT_FALSE(live->stats().halted);

  const auto replayed = make();
  replayed->replay(log);
  EXPECT_EQ(replayed->state().step_count, live->state().step_count);
  EXPECT_EQ(replayed->state().time_s, live->state().time_s);
  ASSERT_EQ(replayed->model().node_count, live->model().node_count);
  EXPECT_TRUE(replayed->state().position_m.x == live->state().position_m.x &&
              replayed->state().position_m.y == live->state().position_m.y &&
              replayed->state().position_m.z == live->state().position_m.z)
      << "the replay's positions differ from the run's";
  EXPECT_TRUE(replayed->state().velocity_m_per_s.x == live->state().velocity_m_per_s.x);

  // One cycle fewer (the one before the last tool change): not the same liver.
  std::vector<SimulationInput> shorter = log;
  for (std::size_t i = shorter.size(); i-- > 0;)
    if (shorter[i].kind == SimulationInput::Kind::cycle && shorter[i].steps > 0) {
      shorter.erase(shorter.begin() + static_cast<std::ptrdiff_t>(i));
      break;
    }
  const auto other = make();
  other->replay(shorter);
  EXPECT_NE(other->state().step_count, live->state().step_count);
  EXPECT_FALSE(other->state().position_m.x == live->state().position_m.x);
}

TEST_F(RealtimeSteppingFixture, AScalpelThatBrokeInCutsWhereverItIsDrawnUntilItIsDrawnOut) {
  const auto model = model_with({});
  RealtimeSimulation simulation(model, make_rest_state(*model));
  simulation.enable_tools(extract_surface(*mesh_));
  // The blade breaks in by the default toughness (200 J/m²: about 0.2 N on its tip).
  simulation.enable_cutting();
  // The blade points down (the tool's −z), its tip 1 mm above the highest node near the middle,
  // long enough to go through the liver there.
  const Eigen::AlignedBox3d box = rest_box(*model);
  const Eigen::Vector2d where(box.center().x() - 0.04, box.center().y());
  const auto [top_m, bottom_m] = column_at(*model, where);
  ASSERT_TRUE(std::isfinite(top_m));
  const double thickness_m = top_m - bottom_m;
  Tool scalpel;
  scalpel.kind = ToolKind::scalpel;
  scalpel.geometry.blade_length_m = thickness_m + 0.03;
  Eigen::Vector3d heel(where.x(), where.y(), top_m + 0.001 + scalpel.geometry.blade_length_m);
  scalpel.pose.origin_m = heel;
  simulation.set_tool(scalpel);
  simulation.start();
  auto move_to = [&](const Eigen::Vector3d& to) {
    scalpel.pose.origin_m = heel = to;
    simulation.set_tool(scalpel);
    return run_until(simulation, 0.01, [](const SimulationSnapshot&) { return false; });
  };

  // Pressed in until it breaks in.
  bool broke_in = false;
  for (int k = 0; k < 150 && !broke_in; ++k)
    broke_in = move_to(heel - Eigen::Vector3d(0.0, 0.0, 2e-4)).hand(Hand::right).blade_cutting;
  ASSERT_TRUE(broke_in) << "pressed 30 mm in, the blade did not break in";
  // In, it passes into the tissue without pushing, on through the liver (so that the stroke
  // passes through whole elements of this coarse mesh, 2 cm across). Held still, the tissue
  // closes over the blade and relaxes (below 300 Pa anywhere).
  while (heel.z() - scalpel.geometry.blade_length_m > bottom_m - 0.005)
    move_to(heel - Eigen::Vector3d(0.0, 0.0, 5e-4));
  run_until(simulation, 0.5, [](const SimulationSnapshot&) { return false; });
  simulation.stop();
  double largest_stress_pa = 0.0;
  for (std::size_t e = 0; e < model->tet_count; ++e)
    largest_stress_pa =
        std::max(largest_stress_pa, element_cutting_stress_pa(*model, simulation.state(), e));
  EXPECT_LT(largest_stress_pa, 300.0) << "the tissue did not relax around the still blade";
  EXPECT_EQ(simulation.snapshot().topology_version, 0u) << "a still blade cut";
  simulation.start();

  // Drawn along, it cuts through the relaxed tissue (8 cm: a stroke that starts and ends inside
  // the tissue separates only the elements it has passed all the way through).
  SimulationSnapshot seen;
  for (int k = 0; k < 80; ++k) seen = move_to(heel + Eigen::Vector3d(1e-3, 0.0, 0.0));
  EXPECT_GT(seen.topology_version, 0u) << "the blade passed through the tissue uncut";
  EXPECT_TRUE(seen.hand(Hand::right).blade_cutting);
  // Drawn out (its tip clear of the tissue), it is out: the next cut needs a new break-in.
  while (heel.z() - scalpel.geometry.blade_length_m < top_m + 0.01)
    seen = move_to(heel + Eigen::Vector3d(0.0, 0.0, 1e-3));
  EXPECT_FALSE(seen.hand(Hand::right).blade_cutting)
      << "the blade drawn out of the tissue still cuts";
  simulation.stop();
  EXPECT_FALSE(simulation.stats().halted);
  EXPECT_EQ(check_health(*simulation.snapshot().model, simulation.state()), HealthProblem::none);
}

TEST_F(RealtimeSteppingFixture, TheForceOnAProbeReachesTheHapticDeviceInNewtons) {
  const auto model = model_with({});
  RealtimeSimulation simulation(model, make_rest_state(*model));
  simulation.enable_tools(extract_surface(*mesh_));
  // A probe pressed 4 mm into the top of the liver, held still.
  const Eigen::Vector2d where = rest_box(*model).center().head<2>();
  const double top_m = column_at(*model, where).top_m;
  ASSERT_TRUE(std::isfinite(top_m));
  Tool probe;
  probe.kind = ToolKind::probe;
  probe.pose.origin_m = {where.x(), where.y(), top_m + probe.geometry.probe_tip_radius_m - 0.004};
  // The device's origin is the probe's point, its axes the scene's.
  ManualDevice device;
  ServoLoop::Options options;
  options.mapping.offset_m = probe.pose.origin_m;
  ServoLoop servo(device, options);
  device.set(Eigen::Vector3d::Zero(), 0);
  simulation.set_haptic_servo(&servo);
  simulation.set_tool(probe);
  servo.start();
  simulation.start();
  EXPECT_THROW(simulation.set_haptic_servo(nullptr), std::logic_error) << "only while stopped";
  run_until(simulation, 1.0, [](const SimulationSnapshot&) { return false; });
  // Stopped, the simulation's last model stands until it goes stale: within the rate limit's few
  // ticks the device renders the force of the last snapshot, in newtons.
  simulation.stop();
  const auto stopped = std::chrono::steady_clock::now();
  simulation.update_snapshot();
  const Eigen::Vector3d simulated_n = simulation.snapshot().hand(Hand::right).force_n;
  ASSERT_GT(simulated_n.norm(), 0.05) << "the probe pressed nothing";
  // A stall of this shared machine trips the watchdog, and its ramp back up takes 0.05 s (the CI
  // once read 77 % of the force): wait for the full force, well before the model goes stale
  // (0.1 s after its last publication, which was before the stop).
  ServoFrame frame;
  while (std::chrono::steady_clock::now() < stopped + std::chrono::milliseconds(80)) {
    if (servo.newest_frame(frame) && (frame.force_n - simulated_n).norm() < 1e-9) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_TRUE(servo.newest_frame(frame));
  EXPECT_LT((frame.force_n - simulated_n).norm(), 1e-9)
      << "device " << frame.force_n.transpose() << " N, simulation " << simulated_n.transpose()
      << " N; watchdog trips " << servo.stats().watchdog_trips;
  EXPECT_GT(frame.force_n.z(), 0.0) << "the tissue pushes the probe up";
  // No new model: the watchdog takes the force away (stale after 0.1 s, then a 0.05 s ramp).
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_TRUE(servo.newest_frame(frame));
  EXPECT_EQ(frame.force_n, Eigen::Vector3d::Zero()) << "a stale model still pushes";
  EXPECT_GE(servo.stats().watchdog_trips, 1u);
  servo.stop();
  EXPECT_EQ(device.last_force_n(), Eigen::Vector3d::Zero()) << "force left on after stop";
}

// A scripted device in each hand (issue 43): the left one's forceps close on the marked node and
// lift it while the right one's probe presses the top; each tool is where its own device's mapping
// puts it, and each device is pushed by its own tool's tissue.
TEST_F(RealtimeSteppingFixture, TwoScriptedDevicesMoveAToolEachAndEachFeelsItsOwn) {
  const auto model = model_with({});
  RealtimeSimulation simulation(model, make_rest_state(*model));
  simulation.enable_tools(extract_surface(*mesh_));
  const NodeIndex node = anterior_marked_node(*mesh_);
  const Eigen::Vector3d marked = model->rest_position_m.at(node);
  DeviceToolSettings forceps, probe;
  forceps.kind = ToolKind::forceps;
  probe.kind = ToolKind::probe;
  const Eigen::AlignedBox3d box = rest_box(*model);
  ServoLoop::Options options;
  options.left_mapping.offset_m = marked - forceps_grasp_point_m(device_tool(forceps, {}, 1));
  options.mapping.offset_m = {box.center().x(), box.center().y(), box.max().z()};
  // Left: open, 15 mm above; down; closed from 0.6 s; lifted 25 mm over 1 s. Right: from 10 mm
  // above the top's highest point, pressed 8 mm down over 1 s.
  TrajectoryDevice left("left script", {{0.0, {0.0, 0.0, 15.0}, 0},
                                        {0.4, {0.0, 0.0, 0.0}, 0},
                                        {0.6, {0.0, 0.0, 0.0}, 1},
                                        {1.0, {0.0, 0.0, 0.0}, 1},
                                        {2.0, {0.0, 0.0, 25.0}, 1},
                                        {30.0, {0.0, 0.0, 25.0}, 1}});
  TrajectoryDevice right(
      "right script",
      {{0.0, {0.0, 0.0, 10.0}, 0}, {1.0, {0.0, 0.0, -8.0}, 0}, {30.0, {0.0, 0.0, -8.0}, 0}});
  // Both play on the simulation's time: a loaded machine (a sanitizer build beside other work)
  // slows the simulation, and a script on the wall clock then closed and lifted the forceps at
  // other moments of the simulated motion (the node came up 1.6 mm, not 5).
  left.play_on(&simulation.simulated_time_s());
  right.play_on(&simulation.simulated_time_s());
  ServoLoop servo(right, left, options);
  simulation.set_haptic_servo(&servo);
  simulation.set_device_tool(Hand::left, forceps);
  simulation.set_device_tool(Hand::right, probe);
  simulation.log_inputs(true);
  servo.start();
  simulation.start();
  const SimulationSnapshot both = run_until(simulation, 60.0, [&](const SimulationSnapshot& s) {
    return s.hand(Hand::left).grasping && s.position_m.z[node] - marked.z() > 0.005 &&
           s.hand(Hand::right).force_n.z() > 0.05;
  });
  simulation.stop();
  servo.stop();
  const HandSnapshot& l = both.hand(Hand::left);
  const HandSnapshot& r = both.hand(Hand::right);
  ASSERT_TRUE(l.grasping) << "the left hand's forceps took no hold";
  ASSERT_GT(both.position_m.z[node] - marked.z(), 0.005) << "the held node was not lifted";
  ASSERT_GT(r.force_n.z(), 0.05) << "the right hand's probe pressed nothing";
  ASSERT_TRUE(l.tool && l.device_sample && r.tool && r.device_sample);
  EXPECT_EQ(l.tool->kind, ToolKind::forceps);
  EXPECT_EQ(r.tool->kind, ToolKind::probe);
  EXPECT_LT(
      (l.tool->pose.origin_m - options.left_mapping.scene_position_m(l.device_sample->position_mm))
          .norm(),
      1e-12);
  EXPECT_LT((r.tool->pose.origin_m - options.mapping.scene_position_m(r.device_sample->position_mm))
                .norm(),
            1e-12);
  EXPECT_LT(l.force_n.z(), 0.0) << "the tissue pulls the forceps back down";
  // Each device was pushed by its own tool: the probe's up, the forceps' down.
  double right_up = 0.0, left_down = 0.0;
  ServoFrame frame;
  while (servo.next_logged_frame(Hand::right, frame))
    right_up = std::max(right_up, frame.force_n.z());
  while (servo.next_logged_frame(Hand::left, frame))
    left_down = std::max(left_down, -frame.force_n.z());
  EXPECT_GT(right_up, 0.0) << "the right device never felt its probe";
  EXPECT_GT(left_down, 0.0) << "the left device never felt its forceps";
  EXPECT_FALSE(simulation.stats().halted);
  // The log keeps one tool a hand between cycles: each device moves its tool at every loop, and
  // a tool no cycle used is replaced by the hand's next one, whatever the other hand took between.
  std::array<int, 2> tools_since_cycle{};
  int cycles = 0;
  for (const SimulationInput& input : simulation.take_input_log()) {
    if (input.kind == SimulationInput::Kind::cycle) {
      tools_since_cycle = {};
      ++cycles;
    } else if (input.kind == SimulationInput::Kind::tool && input.tool) {
      EXPECT_LE(++tools_since_cycle[hand_index(input.hand)], 1)
          << "two tools of the " << hand_name(input.hand) << " hand before cycle " << cycles;
    }
  }
  // Cycles came (their number follows the machine's speed: a sanitizer's build takes fewer, longer
  // ones to the same simulated time).
  EXPECT_GT(cycles, 1);
}

// The tool follows the stylus (issue 43, item 2): a scripted stylus turning from upright to 60°
// about x, through a mapping turned about y; the tool's orientation is the stylus's turned by
// the mapping, frame by frame.
TEST_F(RealtimeSteppingFixture, TheDevicesToolTurnsWithAScriptedStylus) {
  const auto model = model_with({});
  RealtimeSimulation simulation(model, make_rest_state(*model));
  simulation.enable_tools(extract_surface(*mesh_));
  const Eigen::Quaterniond upright = Eigen::Quaterniond::Identity();
  const Eigen::Quaterniond tilted(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitX()));
  ServoLoop::Options options;
  options.mapping.rotation = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY());
  options.mapping.offset_m = {0.0, 0.0, 0.3};  // far above the liver: nothing is touched
  TrajectoryDevice device("turning stylus", {{0.0, {0.0, 0.0, 0.0}, 0, upright},
                                             {2.0, {0.0, 0.0, 0.0}, 0, tilted},
                                             {60.0, {0.0, 0.0, 0.0}, 0, tilted}});
  ServoLoop servo(device, options);
  DeviceToolSettings scalpel;
  scalpel.kind = ToolKind::scalpel;
  simulation.set_haptic_servo(&servo);
  simulation.set_device_tool(scalpel);
  servo.start();
  simulation.start();
  int checked = 0;
  run_until(simulation, 60.0, [&](const SimulationSnapshot& seen) {
    const HandSnapshot& hand = seen.hand(Hand::right);
    if (!hand.tool || !hand.device_sample || !hand.device_sample->orientation) return false;
    EXPECT_LT(hand.tool->pose.orientation.angularDistance(options.mapping.rotation *
                                                          *hand.device_sample->orientation),
              1e-12);
    ++checked;
    return hand.device_sample->orientation->angularDistance(tilted) < 1e-9;
  });
  simulation.stop();
  servo.stop();
  EXPECT_GT(checked, 1) << "the tool was never seen with the stylus's orientation";
  const HandSnapshot& last = simulation.snapshot().hand(Hand::right);
  ASSERT_TRUE(last.tool);
  EXPECT_LT(last.tool->pose.orientation.angularDistance(options.mapping.rotation * tilted), 1e-9)
      << "the tool did not end turned as the stylus";
}

// A scripted device holds the forceps (issue 8): the servo's mapping puts the device's origin on
// the forceps' origin over a marked node; the open jaws come down into the tissue, the action
// button closes them on it, the
// device lifts 10 mm and the liver comes with it; the force model reaches the device, pulling it
// back down; the button released lets go.
TEST_F(RealtimeSteppingFixture, AScriptedDeviceHoldsTheForcepsPullsTheLiverAndFeelsItPullBack) {
  const auto model = model_with({});
  RealtimeSimulation simulation(model, make_rest_state(*model));
  simulation.enable_tools(extract_surface(*mesh_));
  const NodeIndex node = anterior_marked_node(*mesh_);
  const Eigen::Vector3d marked = model->rest_position_m.at(node);
  DeviceToolSettings held;
  held.kind = ToolKind::forceps;
  Tool closed = device_tool(held, Eigen::Vector3d::Zero(), 1);
  ServoLoop::Options options;
  options.mapping.offset_m = marked - forceps_grasp_point_m(closed);  // device origin → grasp
  // Open, 15 mm above; down to the origin (the open jaws push the tissue down by about 1 cm);
  // closed from 0.6 s; lifted by 25 mm over 1 s, held, let go at 30 s.
  TrajectoryDevice device("script", {{0.0, {0.0, 0.0, 15.0}, 0},
                                     {0.4, {0.0, 0.0, 0.0}, 0},
                                     {0.6, {0.0, 0.0, 0.0}, 1},
                                     {1.0, {0.0, 0.0, 0.0}, 1},
                                     {2.0, {0.0, 0.0, 25.0}, 1},
                                     {30.0, {0.0, 0.0, 25.0}, 0}});
  ServoLoop servo(device, options);
  simulation.set_haptic_servo(&servo);
  simulation.set_device_tool(held);
  simulation.set_tool(std::nullopt);  // ignored while the device holds a tool
  servo.start();
  simulation.start();
  const SimulationSnapshot grasped =
      run_until(simulation, 60.0,
                [](const SimulationSnapshot& seen) { return seen.hand(Hand::right).grasping; });
  ASSERT_TRUE(grasped.hand(Hand::right).grasping) << "the jaws closed by the button took no hold";
  ASSERT_TRUE(grasped.hand(Hand::right).tool && grasped.hand(Hand::right).device_sample);
  EXPECT_EQ(grasped.hand(Hand::right).tool->kind, ToolKind::forceps);
  EXPECT_EQ(grasped.hand(Hand::right).tool->jaw_opening, 0.0);
  EXPECT_LT((grasped.hand(Hand::right).tool->pose.origin_m -
             options.mapping.scene_position_m(grasped.hand(Hand::right).device_sample->position_mm))
                .norm(),
            1e-12)
      << "the tool is not where the mapping puts the device";
  // Lifted: the held node comes up above where it was at rest.
  const SimulationSnapshot lifted = run_until(simulation, 60.0, [&](const SimulationSnapshot& s) {
    return s.position_m.z[node] - marked.z() > 0.005;
  });
  EXPECT_GT(lifted.position_m.z[node] - marked.z(), 0.005);
  EXPECT_TRUE(lifted.hand(Hand::right).grasping);
  EXPECT_LT(lifted.hand(Hand::right).force_n.z(), 0.0) << "the tissue pulls the forceps back down";
  simulation.stop();  // the last model stands for the servo until it goes stale
  servo.stop();
  EXPECT_GT(servo.stats().ticks, 0u);
  EXPECT_LT(servo.stats().max_force_n, servo.safety().force_cap_n + 1e-12);
  EXPECT_FALSE(simulation.stats().halted);
  // Without the device's tool, set_tool's acts again.
  simulation.set_device_tool(std::nullopt);
  Tool probe;
  probe.pose.origin_m = marked + Eigen::Vector3d(0.0, 0.0, 0.05);
  simulation.set_tool(probe);
  simulation.start();
  // The first snapshots may still be the last cycle's before the stop.
  const SimulationSnapshot after = run_until(simulation, 60.0, [](const SimulationSnapshot& seen) {
    return seen.hand(Hand::right).tool && seen.hand(Hand::right).tool->kind == ToolKind::probe;
  });
  simulation.stop();
  ASSERT_TRUE(after.hand(Hand::right).tool);
  EXPECT_EQ(after.hand(Hand::right).tool->kind, ToolKind::probe);
  EXPECT_TRUE(after.hand(Hand::right).device_sample) << "the servo's frames are still read";
  EXPECT_FALSE(after.hand(Hand::right).grasping)
      << "the forceps let go when the device put them down";
}

// The mouse puts the device's tool down where it presses: a frame stamped before the press, with
// the device still where the last press left it, never shows the tool there.
TEST_F(RealtimeSteppingFixture, FramesFromBeforeTheDeviceToolWasSetAreNotTaken) {
  const auto model = model_with({});
  RealtimeSimulation simulation(model, make_rest_state(*model));
  simulation.enable_tools(extract_surface(*mesh_));
  ManualDevice device;
  ServoLoop::Options options;  // device mm = scene mm
  options.mapping.scale = 1.0;
  ServoLoop servo(device, options);  // not started: the test ticks it
  const Eigen::Vector3d old_mm(0.0, 0.0, 500.0), new_mm(0.0, 0.0, 400.0);
  device.place(old_mm, 0);
  servo.tick(1.0);
  simulation.set_haptic_servo(&servo);
  simulation.set_device_tool(DeviceToolSettings{}, 2.0);
  simulation.start();
  const SimulationSnapshot before = run_until(simulation, 0.05, [](const SimulationSnapshot& seen) {
    return seen.hand(Hand::right).tool.has_value();
  });
  EXPECT_FALSE(before.hand(Hand::right).tool)
      << "the frame of t = 1 s, before the press at 2 s, was taken";
  ASSERT_TRUE(before.hand(Hand::right).device_sample) << "the frame itself was read";
  device.place(new_mm, 0);
  servo.tick(2.0);
  const SimulationSnapshot after = run_until(simulation, 1.0, [](const SimulationSnapshot& seen) {
    return seen.hand(Hand::right).tool.has_value();
  });
  simulation.stop();
  ASSERT_TRUE(after.hand(Hand::right).tool) << "the frame stamped at the press was not taken";
  EXPECT_LT((after.hand(Hand::right).tool->pose.origin_m - new_mm * 1e-3).norm(), 1e-12);
}

// The blade breaks in by the toughness of the tissue it presses on (RegionMaterial): pressed in
// step by step at the same place, it goes deeper into tissue ten times as tough before it does.
TEST_F(RealtimeSteppingFixture, ABladeBreaksIntoTougherTissueOnlyUnderAHarderPress) {
  auto depth_at_break_in_m = [](double toughness_j_per_m2) {
    ModelOptions options;
    options.fixed_nodes = mesh_->node_sets.at("ligament");
    options.regions[0].fracture_toughness_j_per_m2 = toughness_j_per_m2;
    const auto model = std::make_shared<const SimModel>(build_model(*mesh_, options));
    RealtimeSimulation simulation(model, make_rest_state(*model));
    simulation.enable_tools(extract_surface(*mesh_));
    simulation.enable_cutting();
    const Eigen::AlignedBox3d box = rest_box(*model);
    const Eigen::Vector2d where(box.center().x() - 0.04, box.center().y());
    const double top_m = column_at(*model, where).top_m;
    Tool scalpel;
    scalpel.kind = ToolKind::scalpel;
    scalpel.geometry.blade_length_m = 0.04;
    const double touching_z_m = top_m + scalpel.geometry.blade_length_m;
    scalpel.pose.origin_m = {where.x(), where.y(), touching_z_m + 0.001};
    simulation.set_tool(scalpel);
    simulation.start();
    double depth_m = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 300; ++k) {  // up to 30 mm
      scalpel.pose.origin_m.z() -= 1e-4;
      simulation.set_tool(scalpel);
      if (run_until(simulation, 0.01, [](const SimulationSnapshot&) { return false; })
              .hand(Hand::right)
              .blade_cutting) {
        depth_m = touching_z_m - scalpel.pose.origin_m.z();
        break;
      }
    }
    simulation.stop();
    EXPECT_FALSE(simulation.stats().halted);
    return depth_m;
  };
  const double liver_m = depth_at_break_in_m(200.0), tough_m = depth_at_break_in_m(2000.0);
  std::cout << "the blade broke in with its tip " << liver_m * 1e3
            << " mm below the highest node near it at 200 J/m², " << tough_m * 1e3
            << " mm at 2000 J/m²\n";
  ASSERT_TRUE(std::isfinite(liver_m)) << "pressed 30 mm in, the blade did not break into liver";
  EXPECT_GT(tough_m, liver_m + 0.001) << "tissue ten times as tough gave way as soon";
}

// A disarmed blade (the cut button up) only pushes: pressed far past the point where an armed one
// breaks in, it never does; armed, it breaks in.
TEST_F(RealtimeSteppingFixture, ADisarmedScalpelPressesButNeverBreaksIn) {
  const auto model = model_with({});
  RealtimeSimulation simulation(model, make_rest_state(*model));
  simulation.enable_tools(extract_surface(*mesh_));
  simulation.enable_cutting();  // the default toughness, as in the break-in test above
  const Eigen::AlignedBox3d box = rest_box(*model);
  const Eigen::Vector2d where(box.center().x() - 0.04, box.center().y());
  const double top_m = column_at(*model, where).top_m;
  ASSERT_TRUE(std::isfinite(top_m));
  Tool scalpel;
  scalpel.kind = ToolKind::scalpel;
  scalpel.blade_armed = false;
  scalpel.geometry.blade_length_m = 0.04;
  scalpel.pose.origin_m = {where.x(), where.y(), top_m + 0.001 + scalpel.geometry.blade_length_m};
  simulation.set_tool(scalpel);
  simulation.start();
  auto press = [&](double by_m) {
    scalpel.pose.origin_m.z() -= by_m;
    simulation.set_tool(scalpel);
    return run_until(simulation, 0.01, [](const SimulationSnapshot&) { return false; });
  };
  SimulationSnapshot seen;
  for (int k = 0; k < 100; ++k) seen = press(2e-4);  // 20 mm
  EXPECT_FALSE(seen.hand(Hand::right).blade_cutting) << "a disarmed blade broke in";
  EXPECT_EQ(seen.topology_version, 0u);
  EXPECT_GT(seen.hand(Hand::right).contacts, 0u) << "the blade pressed nothing";
  scalpel.blade_armed = true;
  for (int k = 0; k < 150 && !seen.hand(Hand::right).blade_cutting; ++k) seen = press(1e-4);
  simulation.stop();
  EXPECT_TRUE(seen.hand(Hand::right).blade_cutting) << "armed, the pressed blade did not break in";
  EXPECT_FALSE(simulation.stats().halted);
}

}  // namespace
}  // namespace liversim
