// Two hands at once (issue 43, item 1), in the real-time loop run in simulated time
// (RealtimeSimulation::replay, one cycle a millisecond): forceps in the left hand hold the tissue
// while the scalpel in the right hand cuts, both in the same steps; the hold goes on through every
// cut the other hand makes, and the held tissue follows the forceps afterwards.
#include "block_mesh.h"

#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"
#include "liversim/engine/surface.h"
#include "liversim/simulation/realtime_simulation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <vector>

namespace liversim {
namespace {

constexpr double kTopM = 0.04;
constexpr double kCycleS = 1e-3;

// One cycle with each hand's tool at its pose (none: the hand is empty), as the loop logs it.
void add_cycle(std::vector<SimulationInput>& inputs, const std::optional<Tool>& right,
               const std::optional<Tool>& left, int steps) {
  for (const auto& [hand, tool] : {std::pair{Hand::right, right}, std::pair{Hand::left, left}}) {
    SimulationInput taken;
    taken.kind = SimulationInput::Kind::tool;
    taken.hand = hand;
    taken.tool = tool;
    inputs.push_back(taken);
  }
  SimulationInput cycle;
  cycle.kind = SimulationInput::Kind::cycle;
  cycle.steps = steps;
  inputs.push_back(cycle);
}

// The mean height of the block's top nodes within `radius_m` of (x, y) at rest.
double top_height_near(const SimModel& model, const NodeArray& position_m, double x, double y,
                       double radius_m) {
  double sum = 0.0;
  int count = 0;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    const Eigen::Vector3d rest = model.rest_position_m.at(n);
    if (std::abs(rest.z() - kTopM) < 1e-9 && std::hypot(rest.x() - x, rest.y() - y) < radius_m) {
      sum += position_m.z[n];
      ++count;
    }
  }
  return count > 0 ? sum / count : NAN;
}

// A 6 × 5 × 4 cm block held at its base. The left hand's forceps, upright over the top near one
// end (x = 5 cm), close on it and hold; the right hand's scalpel, put in 15 mm deep at x = 1 cm,
// is drawn 2 cm along x at 2 cm/s, cutting, while the forceps hold; then the scalpel is taken
// away and the forceps lift 5 mm in 0.1 s and keep there for 0.2 s.
TEST(TwoHands, ForcepsInOneHandKeepTheirHoldWhileTheScalpelInTheOtherCuts) {
  const TetMesh mesh = testing::block_mesh(6, 5, 4, {0.06, 0.05, kTopM});
  ModelOptions options;
  options.mass_damping_per_s = 30.0;
  for (std::size_t n = 0; n < mesh.node_count(); ++n)
    if (mesh.rest_position_m.z[n] < 1e-9) options.fixed_nodes.push_back(static_cast<NodeIndex>(n));
  const auto model = std::make_shared<const SimModel>(build_model(mesh, options));
  RealtimeSimulation simulation(model, make_rest_state(*model));
  simulation.enable_tools(extract_surface(mesh));
  simulation.enable_cutting();
  const int steps = std::max(1, static_cast<int>(std::lround(kCycleS / realtime_step_s(*model))));

  Tool forceps;  // jaws down, closed: they take the top within the grasp radius of the jaws
  forceps.kind = ToolKind::forceps;
  forceps.jaw_opening = 0.0;
  const Eigen::Vector3d hold(0.05, 0.025, kTopM + forceps.geometry.jaw_length_m - 0.002);
  forceps.pose.origin_m = hold;
  Tool scalpel;
  scalpel.kind = ToolKind::scalpel;
  const Eigen::Vector3d in(0.01, 0.025, kTopM - 0.015 + scalpel.geometry.blade_length_m);
  constexpr double kSpeedMPerS = 0.02, kTravelM = 0.02, kLiftM = 0.005;

  std::vector<SimulationInput> inputs;
  for (int c = 0; c < 50; ++c) add_cycle(inputs, std::nullopt, forceps, steps);  // take hold
  const std::size_t cut_from = inputs.size() / 3;
  const int draw_cycles = static_cast<int>(std::lround(kTravelM / kSpeedMPerS / kCycleS));
  for (int c = 0; c <= draw_cycles; ++c) {
    scalpel.pose.origin_m = in + Eigen::Vector3d(kTravelM * c / draw_cycles, 0.0, 0.0);
    add_cycle(inputs, scalpel, forceps, steps);
  }
  const std::size_t cut_to = inputs.size() / 3;
  for (int c = 1; c <= 100; ++c) {
    forceps.pose.origin_m = hold + Eigen::Vector3d(0.0, 0.0, kLiftM * c / 100.0);
    add_cycle(inputs, std::nullopt, forceps, steps);
  }
  for (int c = 0; c < 200; ++c) add_cycle(inputs, std::nullopt, forceps, steps);

  std::size_t cycle = 0;
  int cycles_holding_while_cutting = 0, cuts_while_holding = 0, hold_lost_at = -1;
  double held_height_before_m = NAN;
  simulation.replay(inputs, [&](const StepReport&, bool parted) {
    simulation.update_snapshot();
    const SimulationSnapshot& seen = simulation.snapshot();
    const HandSnapshot& left = seen.hand(Hand::left);
    const HandSnapshot& right = seen.hand(Hand::right);
    if (cycle == 49) {
      EXPECT_TRUE(left.grasping) << "the forceps closed on the top took no hold";
      EXPECT_FALSE(right.tool) << "the right hand holds a tool it was not given";
      held_height_before_m =
          top_height_near(*seen.model, seen.position_m, hold.x(), hold.y(), 0.008);
    }
    if (cycle >= cut_from && cycle < cut_to) {
      EXPECT_TRUE(right.tool && right.tool->kind == ToolKind::scalpel);
      EXPECT_TRUE(left.tool && left.tool->kind == ToolKind::forceps);
      if (left.grasping && right.blade_cutting) ++cycles_holding_while_cutting;
      if (parted && left.grasping) ++cuts_while_holding;
    }
    if (cycle >= 49 && !left.grasping && hold_lost_at < 0) hold_lost_at = static_cast<int>(cycle);
    ++cycle;
  });
  ASSERT_EQ(cycle, inputs.size() / 3);
  EXPECT_EQ(hold_lost_at, -1) << "the forceps let go at cycle " << hold_lost_at
                              << " (the scalpel cut from cycle " << cut_from << ")";
  EXPECT_GT(cycles_holding_while_cutting, draw_cycles / 2)
      << "the scalpel seldom cut while the forceps held";
  EXPECT_GT(cuts_while_holding, 0) << "no cut parted tissue while the forceps held";
  ASSERT_GT(simulation.model().node_count, model->node_count) << "the scalpel cut nothing";

  // After the cuts, the held tissue still follows the forceps: lifted 5 mm, the top under them
  // rises (by less: the block, fixed at its base, stretches and the hold's springs give), and the
  // tissue pulls them back down.
  simulation.update_snapshot();
  const SimulationSnapshot& lifted = simulation.snapshot();
  const double held_height_after_m =
      top_height_near(*lifted.model, lifted.position_m, hold.x(), hold.y(), 0.008);
  std::cout << "the top under the forceps rose "
            << (held_height_after_m - held_height_before_m) * 1e3
            << " mm when they lifted 5 mm; the tissue's force on them "
            << lifted.hand(Hand::left).force_n.transpose() << " N\n";
  EXPECT_GT(held_height_after_m - held_height_before_m, 0.5 * kLiftM);
  EXPECT_LT(held_height_after_m - held_height_before_m, kLiftM);
  EXPECT_LT(lifted.hand(Hand::left).force_n.z(), 0.0);
  EXPECT_FALSE(lifted.hand(Hand::right).tool);
}

}  // namespace
}  // namespace liversim
