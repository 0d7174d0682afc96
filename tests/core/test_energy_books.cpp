// The energy books (core/energy.h): work of loads and tools booked by advance(), energy held, and
// what the Maxwell arms' dashpots dissipated.
#include "block_mesh.h"

#include "liversim/engine/energy.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"

#include <gtest/gtest.h>

#include <cmath>

namespace liversim {
namespace {

SimModel bar_model(IntegratorKind kind, bool viscous, const TetMesh& mesh) {
  ModelOptions options;
  options.regions[0].tissue = TissueMaterial{3500.0, 0.45, 1060.0};
  if (viscous) options.regions[0].viscoelastic = ViscoelasticParameters{2000.0, 1500.0, 100.0};
  options.fixed_nodes = nodes_on_plane(mesh, 0, 0.0);
  options.mass_damping_per_s = 0.0;  // what is dissipated is the dashpots' (and the scheme's)
  options.integrator.kind = kind;
  options.integrator.step_s = is_explicit(kind) ? 0.0 : 2e-4;
  return build_model(mesh, options);
}

// A small pull (strain ~ 0.1 %: the arm's small-strain energy is exact to that order), held. The
// books must close: what went in is held or was dissipated by the dashpots, up to the scheme's
// error — leapfrog's O(Δt²) modified energy, a few per mille here; backward Euler at 0.2 ms adds
// its own numerical dissipation α_num ~ ω²Δt/2 for the slow modes it resolves, under 5 %.
TEST(EnergyBooks, WhatTheDashpotsDissipateClosesTheBooks) {
  const TetMesh mesh = testing::block_mesh(4, 1, 1, {0.04, 0.01, 0.01});
  std::vector<PointLoad> loads;
  for (const PointLoad& load : end_face_tension(mesh, 3.5))
    if (load.force_n.x() > 0.0) loads.push_back(load);
  for (IntegratorKind kind :
       {IntegratorKind::central_difference, IntegratorKind::rk4, IntegratorKind::backward_euler}) {
    const SimModel model = bar_model(kind, true, mesh);
    SimState state = make_rest_state(model);
    for (int i = 0; i < 50; ++i) advance(model, state, {loads, {}}, 0.01);
    const EnergyBalance books = energy_balance(model, state, {loads, {}});
    EXPECT_GT(books.tool_work_j, 0.0);
    EXPECT_GT(books.viscous_dissipated_j, 0.1 * books.tool_work_j)
        << integrator_name(kind) << ": τ = 0.05 s, the arm relaxed many times over";
    const double unexplained = books.dissipated_j() - books.viscous_dissipated_j;
    EXPECT_LT(std::abs(unexplained), 0.05 * books.tool_work_j) << integrator_name(kind);
  }
}

// An elastic bar has no dashpot: nothing booked as viscous, and leapfrog without damping holds
// what was supplied to O(Δt²).
TEST(EnergyBooks, AnElasticBarHoldsWhatWasSupplied) {
  const TetMesh mesh = testing::block_mesh(4, 1, 1, {0.04, 0.01, 0.01});
  const SimModel model = bar_model(IntegratorKind::central_difference, false, mesh);
  SimState state = make_rest_state(model);
  std::vector<PointLoad> loads;
  for (const PointLoad& load : end_face_tension(mesh, 3.5))
    if (load.force_n.x() > 0.0) loads.push_back(load);
  for (int i = 0; i < 30; ++i) advance(model, state, {loads, {}}, 0.01);
  const EnergyBalance books = energy_balance(model, state, {loads, {}});
  EXPECT_EQ(books.viscous_dissipated_j, 0.0);
  EXPECT_GT(books.tool_work_j, 0.0);
  EXPECT_LT(std::abs(books.dissipated_j()), 0.05 * books.tool_work_j);
}

// A spring whose anchor moves does work: the energy it adds at the moment of the move.
TEST(EnergyBooks, AMovedSpringAnchorBooksTheEnergyItAdds) {
  const TetMesh mesh = testing::block_mesh(4, 1, 1, {0.04, 0.01, 0.01});
  const SimModel model = bar_model(IntegratorKind::central_difference, false, mesh);
  SimState state = make_rest_state(model);
  const NodeIndex node = NodeIndex(mesh.node_count() - 1);
  std::vector<NodeSpring> springs{{node, model.rest_position_m.at(node), 100.0, 0.0}};
  advance(model, state, {{}, springs}, 0.01);
  EXPECT_NEAR(state.energy.tool_work_j, 0.0, 1e-15);  // attached where the node is: no work
  springs[0].anchor_m.y() += 0.002;
  const double added =
      spring_energy_j(springs, state.position_m) -
      0.5 * 100.0 * (state.position_m.at(node) - model.rest_position_m.at(node)).squaredNorm();
  advance(model, state, {{}, springs}, 0.01);
  EXPECT_NEAR(state.energy.tool_work_j, added, 1e-12 * added);
}

}  // namespace
}  // namespace liversim
