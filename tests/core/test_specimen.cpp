// A specimen you lift out (issue 42, item 5), in the real-time loop run in simulated time
// (RealtimeSimulation::replay, one cycle a millisecond): the top of a block cut free stays as a
// body of its own, falls under gravity onto the block and rests on it; pulled out
// of the field it leaves the simulation and is kept as the session's specimen; Session ▸ Remove
// Specimen takes it out at the cycle it was asked for, and a replay does the same.
#include "block_mesh.h"

#include "liversim/engine/energy.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"
#include "liversim/engine/support.h"
#include "liversim/interaction/body_contact.h"
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

TEST(Specimen, AFreedTopDroppedOntoTheOrganFallsAndRestsOnItNotThroughIt) {
  CutBlock block = cut_block();
  const std::vector<FreeBody> bodies = free_bodies(*block.model);
  ASSERT_EQ(bodies.size(), 1u);
  // Let go 20 mm above the cut: it falls onto the block's cut face in about √(2·0.02/g) = 64 ms,
  // and rests there on the body contact (body_contact.h) instead of falling through the block to
  // the support 32 mm below.
  constexpr double kDropM = 0.02;
  const std::vector<std::uint8_t> organ = organ_elements(*block.model);
  std::vector<std::uint8_t> in_body(block.model->node_count, 0);
  for (std::size_t e = 0; e < block.model->tet_count; ++e)
    if (!organ[e])
      for (int c = 0; c < 4; ++c) in_body[block.model->corner[c][e]] = 1;
  for (std::size_t n = 0; n < block.model->node_count; ++n)
    if (in_body[n]) block.state.position_m.z[n] += kDropM;
  open_energy_books(*block.model, block.state);  // the lift's potential energy is what it was given
  RealtimeSimulation simulation(block.model, block.state);
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
  // Falling at about 40 ms, before it meets the block: less than ½·g·t² below where it was let
  // go, and about the fall with the mass damping's drag α = 30/s, (g/α)·(t − (1 − e^(−αt))/α) =
  // 5.5 mm.
  const double t = time_at_40_ms, alpha = 30.0;
  const double dragged_m = kGravity / alpha * (t - (1.0 - std::exp(-alpha * t)) / alpha);
  EXPECT_LT(kCutZ + kDropM - lowest_at_40_ms, 0.5 * kGravity * t * t);
  EXPECT_NEAR(kCutZ + kDropM - lowest_at_40_ms, dragged_m, 0.1 * dragged_m);
  // At rest on the block after 1.5 s, carried by the contact (body_contact.h): its springs push
  // the body up by its weight M·g and the block down by as much (each contact's corners take what
  // its node takes, by construction), to the 2 % the body's remaining motion and the mass damping
  // leave. With one stiffness k for every contact, the underside's mean depth in the block is
  // then M·g / (N·k) over its N nodes: measured by each node's height over its twin on the block's
  // cut face (the node the cut split it from, at the same rest position), within 25 % (the face
  // is dented under the body, and the frictionless body has slid by up to a millimetre), on twins
  // 5 mm or more inside the block's edges (where a corner may hang over the edge).
  const SimModel& model = *end.model;
  const std::vector<std::uint8_t> organ_now = organ_elements(model);
  std::vector<std::uint8_t> body_node(model.node_count, 0), organ_node(model.node_count, 0);
  for (std::size_t e = 0; e < model.tet_count; ++e)
    for (int c = 0; c < 4; ++c) (organ_now[e] ? organ_node : body_node)[model.corner[c][e]] = 1;
  const BoundarySurface surface = boundary_surface(model);
  double body_mass_kg = 0.0, lightest_kg = INFINITY;
  for (const NodeIndex n : surface.nodes)
    lightest_kg = std::min(lightest_kg, model.lumped_mass_kg[n]);
  std::size_t underside = 0;
  std::vector<std::pair<std::size_t, std::size_t>> twins;  // (body node, organ node)
  for (std::size_t n = 0; n < model.node_count; ++n) {
    if (!body_node[n]) continue;
    body_mass_kg += model.lumped_mass_kg[n];
    const Eigen::Vector3d rest = model.rest_position_m.at(n);
    if (std::abs(rest.z() - kCutZ) > 1e-9) continue;
    ++underside;
    if (rest.x() < 0.005 || rest.x() > 0.055 || rest.y() < 0.005 || rest.y() > 0.045) continue;
    for (std::size_t m = 0; m < model.node_count; ++m)
      if (organ_node[m] && (model.rest_position_m.at(m) - rest).norm() < 1e-9)
        twins.emplace_back(n, m);
  }
  ASSERT_GE(twins.size(), 10u);
  BodyContact contact(model, surface, free_bodies(model));
  std::vector<NodeSpring> springs;
  contact.add_springs(model, end.position_m, springs);
  EXPECT_GE(contact.contacts(), underside / 2);
  Eigen::Vector3d on_body = Eigen::Vector3d::Zero(), on_organ = Eigen::Vector3d::Zero();
  for (const NodeSpring& spring : springs)
    (body_node[spring.node] ? on_body : on_organ) +=
        spring.stiffness_n_per_m * (spring.anchor_m - end.position_m.at(spring.node));
  const double weight_n = body_mass_kg * kGravity;
  EXPECT_NEAR(on_body.z(), weight_n, 0.02 * weight_n);
  EXPECT_LT(on_body.head<2>().norm(), 0.02 * weight_n);
  EXPECT_LT((on_body + on_organ).norm(), 1e-9 * weight_n);
  const double omega_c = model.support_frequency_fraction * model.max_frequency_rad_per_s;
  const double mean_depth_m =
      weight_n / static_cast<double>(underside) / (omega_c * omega_c * lightest_kg);
  double mean_gap_m = 0.0;
  for (const auto& [b, o] : twins)
    mean_gap_m += (end.position_m.z[b] - end.position_m.z[o]) / static_cast<double>(twins.size());
  EXPECT_NEAR(-mean_gap_m, mean_depth_m, 0.25 * mean_depth_m);
  const Height rest = body_height(model, end.position_m);
  EXPECT_GT(rest.lowest_m, block.support_z_m + 0.02);  // far above the support
  double fastest = 0.0;
  for (std::size_t n = 0; n < model.node_count; ++n)
    if (body_node[n]) fastest = std::max(fastest, simulation.state().velocity_m_per_s.at(n).norm());
  EXPECT_LT(fastest, 0.01) << "not at rest";
  ::testing::Test::RecordProperty("mean_depth_mm", std::to_string(-mean_gap_m * 1e3));
  ::testing::Test::RecordProperty("expected_mean_depth_mm", std::to_string(mean_depth_m * 1e3));
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
