// The support the organ rests on under gravity (support.h): the organ's underside and the tray
// around it as a height field, a body that falls onto it comes to rest carried by it, and the
// energy books hold its springs.
#include "block_mesh.h"

#include "liversim/engine/energy.h"
#include "liversim/engine/forces.h"
#include "liversim/engine/health.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"
#include "liversim/engine/support.h"
#include "liversim/engine/surface.h"
#include "liversim/meshing/default_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

namespace liversim {
namespace {

constexpr double kEarth = 9.81;
constexpr double kClearance = 1e-4;

// A box 4 × 3 × 2 cm on z = 0 … 2 cm.
TetMesh box() {
  return testing::block_mesh(4, 3, 2, {0.04, 0.03, 0.02});
}

TEST(Support, IsTheUndersideOverTheFootprintAndTheTrayAroundIt) {
  const TetMesh mesh = box();
  const BoundarySurface surface = extract_surface(mesh);
  // Gravity along −z: the underside is the bottom face, z = 0, depth −z = 0; the tray is there too.
  const SupportSurface down = support_under(mesh.rest_position_m, surface, {0.0, 0.0, -kEarth});
  EXPECT_NEAR(down.depth_under({0.02, 0.015, 0.01}).depth_m, kClearance, 1e-12);
  EXPECT_NEAR(down.floor_depth_m, kClearance, 1e-12);
  EXPECT_NEAR(down.depth_under({0.5, 0.5, 0.0}).depth_m, kClearance, 1e-12);  // beyond the grid
  // Gravity along +z: the underside is the top face (depth z = 2 cm) and so is the tray.
  const SupportSurface up = support_under(mesh.rest_position_m, surface, {0.0, 0.0, 1.0});
  EXPECT_NEAR(up.depth_under({0.02, 0.015, 0.0}).depth_m, 0.02 + kClearance, 1e-12);
  // Gravity along −x: the underside is the face x = 0 (depth −x = 0), flat over the footprint.
  const SupportSurface side = support_under(mesh.rest_position_m, surface, {-1.0, 0.0, 0.0});
  const SupportSurface::Depth under = side.depth_under({0.03, 0.01, 0.01});
  EXPECT_NEAR(under.depth_m, kClearance, 1e-12);
  EXPECT_NEAR(under.slope_u, 0.0, 1e-9);
  EXPECT_NEAR(under.slope_v, 0.0, 1e-9);
  EXPECT_THROW(support_under(mesh.rest_position_m, surface, Eigen::Vector3d::Zero()),
               std::invalid_argument);
}

// A wedge-shaped underside: the bed under a sloping face is the slope lowered by its rise over one
// cell (each grid point holds the deepest of the cells around it), and its gradient is the
// face's. Built from a box whose nodes are sheared so that the bottom face rises with x.
TEST(Support, UnderASlopeTheBedHasTheSlopesGradient) {
  TetMesh mesh = box();
  const double rise = 0.25;  // dz/dx of the bottom face
  for (std::size_t n = 0; n < mesh.node_count(); ++n)
    mesh.rest_position_m.z[n] += rise * mesh.rest_position_m.x[n];
  const SupportSurface bed =
      support_under(mesh.rest_position_m, extract_surface(mesh), {0.0, 0.0, -1.0});
  const Eigen::Vector3d point(0.02, 0.015, 0.0);
  const SupportSurface::Depth under = bed.depth_under(point);
  EXPECT_NEAR(under.depth_m, -rise * (point.x() - bed.cell_m) + kClearance, 1e-9);
  // The gradient of the depth −z along the axes across gravity, whichever they are.
  const Eigen::Vector3d gradient = under.slope_u * bed.axis_u + under.slope_v * bed.axis_v;
  EXPECT_NEAR(gradient.x(), -rise, 1e-9);
  EXPECT_NEAR(gradient.y(), 0.0, 1e-9);
}

// The push is the penalty of the distance along the bed's normal, k times it, whatever the slope:
// on a plane falling at rise over run s, a point p past it (along gravity) lies p/√(1 + s²) from
// it. So pressed further along the normal a node meets the stiffness k, the contact frequency
// support_stiffness_per_kg promises: a penalty of the depth along gravity was (1 + s²) times as
// stiff across a slope (×7.25 at s = 2.5), and on the bed's steep rim it loaded the light nodes
// there with several times the organ's weight above them.
TEST(Support, OnASlopeItPushesAlongItsNormalByTheDistanceAlongIt) {
  constexpr double kSlope = 2.5, kStiffness = 100.0, kPast = 0.002, kFurther = 1e-4;
  SupportSurface plane;
  plane.down = {0.0, 0.0, -1.0};
  plane.axis_u = {1.0, 0.0, 0.0};
  plane.axis_v = plane.down.cross(plane.axis_u);
  plane.cell_m = 0.01;
  plane.cells_u = plane.cells_v = 4;
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 4; ++i) plane.depth_m.push_back(kSlope * i * plane.cell_m);
  plane.floor_depth_m = 1.0;
  const Eigen::Vector3d normal = Eigen::Vector3d(kSlope, 0.0, 1.0).normalized();  // out of it
  const Eigen::Vector3d point(0.02, -0.02, -(kSlope * 0.02 + kPast));
  const SupportContact pressed = support_contact(plane, point, point, kStiffness, 0.0);
  const double distance_m = kPast / std::sqrt(1.0 + kSlope * kSlope);
  ASSERT_TRUE(pressed.touching);
  EXPECT_NEAR((pressed.force_n - kStiffness * distance_m * normal).norm(), 0.0,
              1e-12 * kStiffness * distance_m);
  EXPECT_NEAR(pressed.energy_j, 0.5 * kStiffness * distance_m * distance_m,
              1e-12 * kStiffness * distance_m * distance_m);
  const SupportContact deeper =
      support_contact(plane, point - kFurther * normal, point, kStiffness, 0.0);
  EXPECT_NEAR((deeper.force_n - pressed.force_n).dot(normal), kStiffness * kFurther,
              1e-9 * kStiffness * kFurther);
}

SimModel resting_model(const TetMesh& mesh, double damping_per_s,
                       double contact_damping_ratio = 1.0) {
  ModelOptions options;
  options.regions[0].tissue = TissueMaterial{20000.0, 0.3, 1060.0};
  options.mass_damping_per_s = damping_per_s;
  options.support_damping_ratio = contact_damping_ratio;
  options.gravity_m_per_s2 = {0.0, 0.0, -kEarth};
  // The box 5 mm above the support it would rest on.
  TetMesh lifted = mesh;
  for (std::size_t n = 0; n < lifted.node_count(); ++n) lifted.rest_position_m.z[n] += 0.005;
  options.support = std::make_shared<const SupportSurface>(
      support_under(mesh.rest_position_m, extract_surface(mesh), options.gravity_m_per_s2));
  return build_model(lifted, options);
}

TEST(Support, ItsContactFrequencyIsAFractionOfTheMeshsAndLowersTheStepByLittle) {
  const TetMesh mesh = box();
  const SimModel model = resting_model(mesh, 0.0);
  const double omega = model.max_frequency_rad_per_s;
  EXPECT_NEAR(model.support_stiffness_per_kg, 0.04 * omega * omega, 1e-9 * omega * omega);
  // 2/ω against 2/(ω·√1.04): the step is 1.9 % shorter.
  EXPECT_NEAR(model.stable_time_step_s * omega / (2.0 * model.stable_step_safety),
              1.0 / std::sqrt(1.04), 1e-12);
}

// Dropped 5 mm, the box comes to rest on the support, which then carries its whole weight: the
// pushes sum to M·g (equilibrium, to the settling left), and no node sinks deeper than the weight
// of the whole box on its lightest node would push it, M·g/(m_min·ω²).
TEST(Support, ABodyDroppedOntoItComesToRestCarriedByIt) {
  const TetMesh mesh = box();
  const SimModel model = resting_model(mesh, 200.0);
  SimState state = make_rest_state(model);
  advance(model, state, {}, 1.0);
  double mass = 0.0, lightest = INFINITY;
  for (double m : model.lumped_mass_kg) {
    mass += m;
    lightest = std::min(lightest, m);
  }
  NodeArray push;
  push.resize(model.node_count);
  add_support_forces(model, state.position_m, push);
  double carried = 0.0, fastest = 0.0, deepest = 0.0;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    carried += push.z[n];
    fastest = std::max(fastest, state.velocity_m_per_s.at(n).norm());
    deepest = std::max(deepest, -state.position_m.z[n]);
  }
  EXPECT_NEAR(carried, mass * kEarth, 1e-6 * mass * kEarth);
  EXPECT_LT(fastest, 1e-6);
  EXPECT_GT(deepest, kClearance);  // it rests on the support, not above it
  EXPECT_LT(deepest - kClearance, mass * kEarth / (lightest * model.support_stiffness_per_kg));
}

// The built-in liver at rest touches nothing of its own support, whichever way is down: every
// node is at least the clearance above it (the support is the deepest point of the underside over
// each grid point, so between grid points it can only lie deeper).
TEST(Support, NoNodeOfTheLiverAtRestTouchesItsSupport) {
  const SceneSetup scene = default_scene(3841);
  for (const Eigen::Vector3d& down :
       {Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 0, 1)}) {
    const SupportSurface support = support_under(scene.mesh, down);
    int touching = 0;
    double worst_m = -INFINITY;
    for (std::size_t n = 0; n < scene.mesh.node_count(); ++n) {
      const Eigen::Vector3d x = scene.mesh.rest_position_m.at(n);
      const double past = x.dot(support.down) - support.depth_under(x).depth_m;
      worst_m = std::max(worst_m, past);
      touching += past > -0.5 * kClearance;
    }
    EXPECT_EQ(touching, 0) << "down " << down.transpose() << ": deepest node " << worst_m * 1e3
                           << " mm past the support";
  }
}

// The real-time loop steps through the guard, which bounds each node's kinetic energy by the
// energy supplied: what gravity releases as the organ comes down counts, so a box let go above its
// support falls onto it and settles without a single step undone, its books closing.
// The moulded bed rises to the liver's rim within a cell or two; the penalty pushes along the
// support's gradient, so such a wall pushed a rim node sideways many times harder than up, and the
// sagging liver's rim chattered against it at metres per second (the wedge resection with gravity
// ran at a tenth of real time). The support is deepened so that it nowhere rises more steeply than
// kSupportMaxSlope; the bilinear slope inside a cell is a mean of its sides' and obeys it too.
TEST(Support, NowhereRisesMoreSteeplyThanItsSlopeLimit) {
  const SceneSetup scene = default_scene(3841);
  const BoundarySurface surface = extract_surface(scene.mesh);
  for (const Eigen::Vector3d& down :
       {Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 0, 1)}) {
    auto steepest = [&](const SupportSurface& support) {
      double worst = 0.0;
      for (int j = 0; j < support.cells_v; ++j)
        for (int i = 0; i < support.cells_u; ++i)
          for (const double a : {0.01, 0.5, 0.99}) {
            const Eigen::Vector3d point =
                (support.origin_u_m + (i + a) * support.cell_m) * support.axis_u +
                (support.origin_v_m + (j + 1.0 - a) * support.cell_m) * support.axis_v;
            const SupportSurface::Depth under = support.depth_under(point);
            worst = std::max({worst, std::abs(under.slope_u), std::abs(under.slope_v)});
          }
      return worst;
    };
    const SupportSurface moulded =
        support_under(scene.mesh.rest_position_m, surface, down, 0.002, 0.05, kClearance, INFINITY);
    EXPECT_GT(steepest(moulded), 5.0) << "down " << down.transpose() << ": the rim's wall";
    const SupportSurface limited = support_under(scene.mesh, down);
    EXPECT_LE(steepest(limited), kSupportMaxSlope + 1e-9) << "down " << down.transpose();
    // Only deepened: nowhere shallower than the moulded bed.
    for (std::size_t k = 0; k < limited.depth_m.size(); ++k)
      ASSERT_GE(limited.depth_m[k], moulded.depth_m[k]) << k;
  }
}

TEST(Support, TheGuardLetsGravityBringTheBodyDownOntoIt) {
  const TetMesh mesh = box();
  const SimModel model = resting_model(mesh, 200.0);
  SimState state = make_rest_state(model);
  StateCheckpoint checkpoint = make_checkpoint(model);
  GuardOptions guard;
  guard.check_energy = true;
  int rollbacks = 0;
  for (int cycle = 0; cycle < 500; ++cycle) {
    const GuardedReport report = guarded_advance(model, state, {}, 1e-3, checkpoint, guard);
    ASSERT_FALSE(report.gave_up) << "cycle " << cycle << ": "
                                 << health_problem_text(report.problem);
    rollbacks += report.rollbacks;
    ASSERT_TRUE(report.energy);
    EXPECT_FALSE(report.energy_created) << "cycle " << cycle;
  }
  EXPECT_EQ(rollbacks, 0);
  double deepest = 0.0;
  for (std::size_t n = 0; n < model.node_count; ++n)
    deepest = std::max(deepest, -state.position_m.z[n]);
  EXPECT_GT(deepest, kClearance) << "it did not come down onto the support";
}

// Undamped (the tissue and the contact), the box falls, hits the support and bounces: the books,
// holding the support's springs (its push and its hold) and gravity's potential, stay at the
// nothing they opened with. RK4, whose velocity is at the
// positions' time (leapfrog's lags half a step, which in free fall alone puts ½·M·g²·Δt·t
// between the books' kinetic and potential energy), at a quarter of its stable step: its energy
// error per period of the fastest mode is O((ωΔt)⁶), and the support's kink at contact costs it
// an O(Δt²) error there. The tolerance is 4 % of the potential given up.
TEST(Support, TheEnergyBooksHoldItsSprings) {
  const TetMesh mesh = box();
  SimModel model = resting_model(mesh, 0.0, 0.0);
  model.integrator.kind = IntegratorKind::rk4;
  model.integrator.step_s = 0.25 * model.stable_time_step_s;
  SimState state = make_rest_state(model);
  bool touched = false;
  for (int i = 0; i < 60; ++i) {
    advance(model, state, {}, 0.001);
    const EnergyBalance books = energy_balance(model, state, {});
    touched |= books.support_j > 0.0;
    EXPECT_NEAR(books.held_j(), 0.0, 0.04 * -books.gravity_j) << "at " << state.time_s << " s";
  }
  EXPECT_TRUE(touched) << "the box never reached the support";
}

// The bed holds what lies on it where it lay, up to μ times its push: the box, settled on its
// support, pulled sideways by a quarter of its weight (a tilt of gravity by 14°) stays where it is
// (its hold yields only to more than μ = 0.5 of its weight); by three quarters of it, more than
// the hold can bear, it slides away, and past kSupportHoldReleaseM the hold lets go.
TEST(Support, HoldsWhatLiesOnItWhereItLayUpToItsFriction) {
  const TetMesh mesh = box();
  auto slide_after_m = [&](double sideways_g) {
    SimModel model = resting_model(mesh, 8.0);
    SimState state = make_rest_state(model);
    advance(model, state, {}, 0.3);  // down onto the support, and settled
    auto centre_x = [&] {
      double sum = 0.0;
      for (std::size_t n = 0; n < model.node_count; ++n) sum += state.position_m.x[n];
      return sum / static_cast<double>(model.node_count);
    };
    const double before_m = centre_x();
    set_gravity(model, {sideways_g * kEarth, 0.0, -kEarth}, model.support);
    advance(model, state, {}, 0.5);
    return centre_x() - before_m;
  };
  EXPECT_EQ(SimModel{}.support_friction_coefficient, 0.5);
  const double held_m = slide_after_m(0.25);
  EXPECT_LT(std::abs(held_m), 1e-3) << "the bed did not hold the box";
  EXPECT_GT(slide_after_m(0.75), kSupportHoldReleaseM) << "the bed held more than its friction";
}

// Touching the bed, a node is damped at ζ = 1 of critical: the box dropped onto its support with
// no other damping comes to rest, where without the contact's damping it keeps bouncing, and the
// books show the energy taken, none made.
TEST(Support, WhatTouchesItIsDampedAndTheBooksShowWhatItTakes) {
  const TetMesh mesh = box();
  auto kinetic_after_j = [&](double ratio, EnergyBalance* books) {
    SimModel model = resting_model(mesh, 0.0, ratio);
    SimState state = make_rest_state(model);
    advance(model, state, {}, 0.3);
    if (books) *books = energy_balance(model, state, {});
    return kinetic_energy_j(model, state.velocity_m_per_s);
  };
  EnergyBalance books;
  const double damped_j = kinetic_after_j(1.0, &books);
  const double undamped_j = kinetic_after_j(0.0, nullptr);
  EXPECT_LT(damped_j, 0.01 * undamped_j) << damped_j << " J against " << undamped_j << " J";
  EXPECT_GT(books.dissipated_j(), 0.9 * -books.gravity_j);
}

TEST(Support, ANegativeOrNotANumberFrictionOrDampingIsRefusedByName) {
  const TetMesh mesh = box();
  auto expect_refused = [&](const ModelOptions& options, const std::string& named) {
    try {
      build_model(mesh, options);
      ADD_FAILURE() << "a bad " << named << " was taken";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  };
  for (const double bad : {-0.1, std::numeric_limits<double>::quiet_NaN()}) {
    ModelOptions friction, damping;
    friction.support_friction_coefficient = bad;
    damping.support_damping_ratio = bad;
    expect_refused(friction, "friction coefficient");
    expect_refused(damping, "damping ratio");
  }
}

}  // namespace
}  // namespace liversim
