// A specimen you lift out (issue 42, item 5), in the real-time loop run in simulated time
// (RealtimeSimulation::replay, one cycle a millisecond): the top of a block cut free stays as a
// body of its own, falls under gravity onto the support under the block and rests there; pulled out
// of the field it leaves the simulation and is kept as the session's specimen; Session ▸ Remove
// Specimen takes it out at the cycle it was asked for, and a replay does the same.
#include "block_mesh.h"

#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"
#include "liversim/engine/support.h"
#include "liversim/interaction/cutting.h"
#include "liversim/simulation/realtime_simulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

namespace liversim {
namespace {

constexpr double kTopM = 0.04, kCutZ = 0.032;
constexpr double kGravity = 9.81;

// A 6 × 5 × 4 cm block held at its bottom, with gravity along −z and the support under it (its
// underside; a tray at its lowest point around it), and its top 8 mm cut free.
struct CutBlock {
  std::shared_ptr<const SimModel> model;
  SimState state;
  double support_z_m = 0.0;  // the support's height under the block
};
CutBlock cut_block() {
  const TetMesh mesh = testing::block_mesh(6, 5, 4, {0.06, 0.05, kTopM});
  ModelOptions options;
  options.mass_damping_per_s = 30.0;
  options.gravity_m_per_s2 = {0.0, 0.0, -kGravity};
  const auto support =
      std::make_shared<const SupportSurface>(support_under(mesh, options.gravity_m_per_s2));
  options.support = support;
  for (std::size_t n = 0; n < mesh.node_count(); ++n)
    if (mesh.rest_position_m.z[n] < 1e-9) options.fixed_nodes.push_back(static_cast<NodeIndex>(n));
  const SimModel model = build_model(mesh, options);
  BladeStroke stroke;
  stroke.add({Eigen::Vector3d(-0.01, -0.01, kCutZ), Eigen::Vector3d(-0.01, 0.06, kCutZ)});
  stroke.add({Eigen::Vector3d(0.07, -0.01, kCutZ), Eigen::Vector3d(0.07, 0.06, kCutZ)});
  CuttingSettings settings;
  settings.cutting_stress_pa = 0.0;
  CutResult cut = cut_tissue(model, make_rest_state(model), stroke, settings);
  EXPECT_TRUE(cut.cut());
  return {std::move(cut.model), std::move(cut.state), -support->floor_depth_m};
}

void add_cycles(std::vector<SimulationInput>& inputs, int cycles, int steps) {
  SimulationInput cycle;
  cycle.kind = SimulationInput::Kind::cycle;
  cycle.steps = steps;
  inputs.insert(inputs.end(), static_cast<std::size_t>(cycles), cycle);
}

int steps_per_ms(const SimModel& model) {
  return std::max(1, static_cast<int>(std::lround(1e-3 / realtime_step_s(model))));
}

// The lowest and the mean z of the free body's nodes.
struct Height {
  double lowest_m = INFINITY, mean_m = 0.0;
};
Height body_height(const SimModel& model, const NodeArray& position_m) {
  Height height;
  int count = 0;
  const std::vector<std::uint8_t> organ = organ_elements(model);
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    if (organ[e]) continue;
    for (int c = 0; c < 4; ++c) {
      const double z = position_m.z[model.corner[c][e]];
      height.lowest_m = std::min(height.lowest_m, z);
      height.mean_m += z;
      ++count;
    }
  }
  height.mean_m /= count;
  return height;
}

TEST(Specimen, AFreedTopFallsUnderGravityAndRestsOnTheSupport) {
  const CutBlock block = cut_block();
  ASSERT_EQ(free_bodies(*block.model).size(), 1u);
  RealtimeSimulation simulation(block.model, block.state);
  // The support is the block's underside (z = 0) less a clearance of 0.1 mm; the body, let go
  // 32 mm above it, falls through the block (bodies do not touch one another) in about
  // √(2·0.032/g) = 81 ms and comes to rest on it.
  EXPECT_NEAR(block.support_z_m, -1e-4, 1e-9);
  std::vector<SimulationInput> inputs;
  add_cycles(inputs, 1500, steps_per_ms(*block.model));
  int cycle = 0;
  double lowest_at_40_ms = 0.0, time_at_40_ms = 0.0;
  simulation.replay(inputs, [&](const StepReport&, bool) {
    if (++cycle != 40) return;
    simulation.update_snapshot();
    const SimulationSnapshot& seen = simulation.snapshot();
    lowest_at_40_ms = body_height(*seen.model, seen.position_m).lowest_m;
    time_at_40_ms = seen.time_s;
  });
  simulation.update_snapshot();
  const SimulationSnapshot& end = simulation.snapshot();
  EXPECT_EQ(end.free_bodies, 1);
  EXPECT_FALSE(simulation.stats().halted);
  // Falling at about 40 ms: less than ½·g·t² below where it was cut, and about the fall with the
  // mass damping's drag α = 30/s, (g/α)·(t − (1 − e^(−αt))/α) = 5.5 mm.
  const double t = time_at_40_ms, alpha = 30.0;
  const double dragged_m = kGravity / alpha * (t - (1.0 - std::exp(-alpha * t)) / alpha);
  EXPECT_LT(kCutZ - lowest_at_40_ms, 0.5 * kGravity * t * t);
  EXPECT_NEAR(kCutZ - lowest_at_40_ms, dragged_m, 0.1 * dragged_m);
  // At rest on the support after 1.5 s: its underside on the support, sunk into it by the penalty
  // spring's sag, at most (the body's weight per node over k = m·ω²) g/ω² with the support's ω.
  const Height rest = body_height(*end.model, end.position_m);
  const double sag_m = kGravity / end.model->support_stiffness_per_kg;
  EXPECT_LE(rest.lowest_m, block.support_z_m + 1e-4);
  EXPECT_GE(rest.lowest_m, block.support_z_m - 4.0 * sag_m - 1e-4);
  // Whole: its mean height is about half its 8 mm thickness over the support.
  EXPECT_NEAR(rest.mean_m - block.support_z_m, 0.004, 0.002);
  double fastest = 0.0;
  const std::vector<std::uint8_t> organ = organ_elements(*end.model);
  for (std::size_t e = 0; e < end.model->tet_count; ++e)
    if (!organ[e])
      for (int c = 0; c < 4; ++c)
        fastest = std::max(fastest,
                           simulation.state().velocity_m_per_s.at(end.model->corner[c][e]).norm());
  EXPECT_LT(fastest, 0.01) << "not at rest";
}

TEST(Specimen, PulledOutOfTheFieldTheBodyLeavesAndIsKeptAsTheSessionsSpecimen) {
  const CutBlock block = cut_block();
  RealtimeSimulation simulation(block.model, block.state);
  simulation.track_outcome(std::nullopt);
  // The hand's grab: springs on the body's nodes pulling it 20 cm up, out of the field (the block's
  // box, 3 cm larger).
  const std::vector<FreeBody> bodies = free_bodies(*block.model);
  ASSERT_EQ(bodies.size(), 1u);
  SimulationInput grab;
  grab.kind = SimulationInput::Kind::springs;
  std::vector<std::uint8_t> taken(block.model->node_count, 0);
  for (const TetIndex e : bodies[0].elements)
    for (int c = 0; c < 4; ++c) {
      const NodeIndex n = block.model->corner[c][e];
      if (taken[n]++) continue;
      const Eigen::Vector3d rest = block.model->rest_position_m.at(n);
      grab.springs.push_back({n, rest + Eigen::Vector3d(0.0, 0.0, 0.2), 0.1, 0.0});
    }
  std::vector<SimulationInput> inputs;
  add_cycles(inputs, 1, steps_per_ms(*block.model));  // the tracking begins
  inputs.push_back(grab);
  add_cycles(inputs, 1000, steps_per_ms(*block.model));
  int taken_out_at = -1, cycle = 0;
  simulation.replay(inputs, [&](const StepReport&, bool) {
    ++cycle;
    simulation.update_snapshot();
    if (taken_out_at < 0 && simulation.snapshot().specimens_taken_out > 0) taken_out_at = cycle;
  });
  const SimulationSnapshot& end = simulation.snapshot();
  ASSERT_GT(taken_out_at, 0) << "the body never left the field";
  EXPECT_EQ(end.specimens_taken_out, 1);
  EXPECT_EQ(end.free_bodies, 0);
  EXPECT_NEAR(end.specimens_taken_out_m3, bodies[0].rest_volume_m3, 1e-12);
  EXPECT_EQ(end.model->tet_count, block.model->tet_count - bodies[0].elements.size());
  const std::optional<OutcomeTracking> outcome = simulation.outcome();
  ASSERT_TRUE(outcome);
  ASSERT_EQ(outcome->tracker.specimens_taken_out().size(), 1u);
  EXPECT_NEAR(outcome->tracker.specimens_taken_out()[0].rest_volume_m3, bodies[0].rest_volume_m3,
              1e-12);
  EXPECT_EQ(outcome->model, end.model);
  // The organ is untouched by it: held at its bottom, its top still near z = 32 mm.
  double top = -INFINITY;
  for (std::size_t n = 0; n < end.model->node_count; ++n) top = std::max(top, end.position_m.z[n]);
  EXPECT_NEAR(top, kCutZ, 1e-3);
}

TEST(Specimen, RemoveSpecimenTakesEveryFreeBodyOutAtItsCycleAndReplaysTheSame) {
  const CutBlock block = cut_block();
  std::vector<SimulationInput> inputs;
  add_cycles(inputs, 30, steps_per_ms(*block.model));
  SimulationInput remove;
  remove.kind = SimulationInput::Kind::take_out_specimens;
  inputs.push_back(remove);
  add_cycles(inputs, 30, steps_per_ms(*block.model));
  auto run = [&] {
    auto simulation = std::make_unique<RealtimeSimulation>(block.model, block.state);
    int cycle = 0, free_at_30 = -1;
    simulation->replay(inputs, [&](const StepReport&, bool) {
      if (++cycle != 30) return;
      simulation->update_snapshot();
      free_at_30 = simulation->snapshot().free_bodies;
    });
    simulation->update_snapshot();
    EXPECT_EQ(free_at_30, 1);  // until asked, the body falls on
    return simulation;
  };
  const auto first = run();
  const auto second = run();
  const SimulationSnapshot& a = first->snapshot();
  const SimulationSnapshot& b = second->snapshot();
  EXPECT_EQ(a.free_bodies, 0);
  EXPECT_EQ(a.specimens_taken_out, 1);
  ASSERT_EQ(a.model->node_count, b.model->node_count);
  for (std::size_t n = 0; n < a.model->node_count; ++n)
    ASSERT_EQ(a.position_m.at(n), b.position_m.at(n)) << "node " << n;
  EXPECT_EQ(a.step_count, b.step_count);
}

}  // namespace
}  // namespace liversim
