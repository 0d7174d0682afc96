// Gravity (the model's effects.gravity): each node carries its weight m·g in every integrator, a
// hanging bar stretches as linear elasticity says, and the energy books hold the gravitational
// potential so that they still close.
#include "block_mesh.h"

#include "liversim/engine/energy.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace liversim {
namespace {

constexpr double kEarth = 9.81;

TEST(Gravity, IsAnEffectOnlyWhenAnAccelerationIsGiven) {
  const TetMesh mesh = testing::block_mesh(2, 1, 1, {0.02, 0.01, 0.01});
  ModelOptions options;
  EXPECT_FALSE(build_model(mesh, options).effects.gravity);
  options.gravity_m_per_s2 = {0.0, 0.0, -kEarth};
  const SimModel model = build_model(mesh, options);
  EXPECT_TRUE(model.effects.gravity);
  EXPECT_EQ(model.gravity_m_per_s2.z(), -kEarth);
  options.gravity_m_per_s2.x() = std::numeric_limits<double>::quiet_NaN();
  try {
    build_model(mesh, options);
    FAIL() << "a NaN gravity built a model";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("gravity"), std::string::npos) << e.what();
  }
}

// A free body falls as a rigid translation: the internal forces stay zero to round-off and every
// node's displacement is what each scheme makes of ẍ = g. Leapfrog (with its half kick at the
// start and across step changes), RK4 and Dormand–Prince integrate a constant acceleration
// exactly: ½·g·t². Backward Euler's velocity gains g·Δt per step and its position takes the new
// velocity, x_N = g·Δt²·N(N + 1)/2 = ½·g·t·(t + Δt). The implicit solve stops at 1e-9 m per node.
TEST(Gravity, AFreeBodyFallsAsEachSchemeIntegratesAConstantAcceleration) {
  const TetMesh mesh = testing::block_mesh(3, 2, 2, {0.03, 0.02, 0.02});
  const double duration_s = 0.1;
  for (IntegratorKind kind :
       {IntegratorKind::central_difference, IntegratorKind::rk4, IntegratorKind::dopri5,
        IntegratorKind::backward_euler}) {
    ModelOptions options;
    options.mass_damping_per_s = 0.0;
    options.gravity_m_per_s2 = {0.0, 0.0, -kEarth};
    options.integrator.kind = kind;
    options.integrator.step_s = is_explicit(kind) ? 0.0 : 0.01;
    const SimModel model = build_model(mesh, options);
    SimState state = make_rest_state(model);
    advance(model, state, {}, duration_s);
    const double t = duration_s;
    const double expected = kind == IntegratorKind::backward_euler
                                ? -0.5 * kEarth * t * (t + options.integrator.step_s)
                                : -0.5 * kEarth * t * t;
    const double tolerance = kind == IntegratorKind::backward_euler ? 1e-8 : 1e-12;
    for (std::size_t n = 0; n < model.node_count; ++n) {
      const Eigen::Vector3d moved = state.position_m.at(n) - model.rest_position_m.at(n);
      ASSERT_NEAR(moved.z(), expected, tolerance) << integrator_name(kind) << ", node " << n;
      ASSERT_NEAR(moved.x(), 0.0, tolerance) << integrator_name(kind) << ", node " << n;
      ASSERT_NEAR(moved.y(), 0.0, tolerance) << integrator_name(kind) << ", node " << n;
    }
  }
}

// A bar of length L held at its top face hangs under its own weight. With ν = 0 the exact
// small-strain answer is uniaxial stress ρ·g·(L − s) at depth s, so the free end drops
// ρ·g·L²/(2E). Each linear tetrahedron's share of a uniform body force is a quarter at each
// corner, which is what m·g on the lumped masses gives, so the only errors are the linear
// elements' (the field is quadratic along the bar: O((h/L)²) = 1 % at ten layers) and geometric
// nonlinearity (O(strain) = 0.1 % at E = 1 MPa). The tolerance is 3 %.
TEST(Gravity, ABarHangingUnderItsOwnWeightStretchesAsLinearElasticitySays) {
  const double length = 0.1, width = 0.01;
  const TetMesh mesh = testing::block_mesh(10, 1, 1, {length, width, width});
  const TissueMaterial material{1e6, 0.0, 1060.0};
  for (IntegratorKind kind : {IntegratorKind::central_difference, IntegratorKind::backward_euler}) {
    ModelOptions options;
    options.regions[0].tissue = material;
    options.fixed_nodes = nodes_on_plane(mesh, 0, 0.0);
    options.gravity_m_per_s2 = {kEarth, 0.0, 0.0};  // down is +x, away from the held face
    // The axial mode (ω = (π/2)·√(E/ρ)/L ≈ 480 rad/s) decays at α/2; the first bending mode
    // (ω ≈ 99 rad/s), which the mesh's asymmetry excites a little, overdamped at ξ = 1.5, at
    // ω·(ξ − √(ξ² − 1)) ≈ 38/s: both are gone to 1e-9 within 0.6 s.
    options.mass_damping_per_s = 300.0;
    options.integrator.kind = kind;
    options.integrator.step_s = is_explicit(kind) ? 0.0 : 1e-3;
    const SimModel model = build_model(mesh, options);
    SimState state = make_rest_state(model);
    advance(model, state, {}, 0.6);
    const double drop = testing::mean_coordinate_on_plane(mesh, state.position_m, 0, length) - length;
    const double expected = material.density_kg_per_m3 * kEarth * length * length /
                            (2.0 * material.youngs_modulus_pa);
    EXPECT_NEAR(drop, expected, 0.03 * expected) << integrator_name(kind);
    // Settled: the nodes no longer move.
    double fastest = 0.0;
    for (std::size_t n = 0; n < model.node_count; ++n)
      fastest = std::max(fastest, state.velocity_m_per_s.at(n).norm());
    EXPECT_LT(fastest * 0.6, 1e-3 * expected) << integrator_name(kind);
  }
}

// Released from rest, an undamped elastic bar held at one end swings and stretches under its
// weight: what gravity's potential loses, kinetic and strain energy gain, and the books (held
// energy including −Σ m·g·(x − X)) stay at the nothing they opened with. At a quarter of the stable
// step leapfrog's energy error is at most (ω_max·Δt/2)² ≈ 4 % of what the fastest modes hold, and
// they hold little of it: the tolerance is 4 % of the potential given up.
TEST(Gravity, TheEnergyBooksHoldTheGravitationalPotential) {
  const TetMesh mesh = testing::block_mesh(6, 1, 1, {0.06, 0.01, 0.01});
  ModelOptions options;
  // Stiff enough to sag 2 mm (qL⁴/8EI), not to flop: the books are tested, not large rotations.
  options.regions[0].tissue = TissueMaterial{1e6, 0.3, 1060.0};
  options.fixed_nodes = nodes_on_plane(mesh, 0, 0.0);
  options.mass_damping_per_s = 0.0;
  options.gravity_m_per_s2 = {0.0, -kEarth, 0.0};  // across the bar: it bends and swings
  SimModel model = build_model(mesh, options);
  model.integrator.step_s = 0.25 * model.stable_time_step_s;
  SimState state = make_rest_state(model);
  for (int i = 0; i < 20; ++i) {
    advance(model, state, {}, 0.01);
    const EnergyBalance books = energy_balance(model, state, {});
    ASSERT_LT(books.gravity_j, 0.0) << "at " << state.time_s << " s the bar has not dropped";
    EXPECT_NEAR(books.held_j(), 0.0, 0.04 * -books.gravity_j) << "at " << state.time_s << " s";
    EXPECT_EQ(books.tool_work_j, 0.0);
  }
}

}  // namespace
}  // namespace liversim
