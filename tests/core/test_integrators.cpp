// Every time integrator: its measured convergence order is the scheme's own (with the viscous
// arm advanced inside the scheme), it reproduces the seed's creep curve (Eq. 3), and the seed's
// unstable recipe (RK4, Δt = 2 ms, ν = 0.49) runs without blowing up and says what it did.
#include "block_mesh.h"

#include "liversim/engine/integrator.h"
#include "liversim/engine/mesh_io.h"
#include "liversim/engine/model_building.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/meshing/liver_geometry.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>

namespace liversim {
namespace {

using testing::block_mesh;

constexpr double kBarLength = 0.04, kBarWidth = 0.01;

RegionMaterial elastic_tissue() {
  RegionMaterial region;
  region.tissue = TissueMaterial{3500.0, 0.3, 1060.0};
  return region;
}

// τ = η1/E1 = 20 ms: the arm relaxes within the 50 ms of the convergence runs.
RegionMaterial fast_viscous_tissue() {
  RegionMaterial region = elastic_tissue();
  region.viscoelastic = ViscoelasticParameters{2000.0, 1500.0, 40.0};
  return region;
}

struct Cantilever {
  TetMesh mesh = block_mesh(4, 1, 1, {kBarLength, kBarWidth, kBarWidth});
  ModelOptions options;

  explicit Cantilever(const RegionMaterial& material) {
    options.regions[0] = material;
    for (std::size_t n = 0; n < mesh.node_count(); ++n)
      if (mesh.rest_position_m.x[n] < 1e-12) options.fixed_nodes.push_back(NodeIndex(n));
  }

  // Released from a smooth bent shape, free vibration for `duration_s`: the final positions.
  NodeArray run(IntegratorKind kind, double step_s, double duration_s, StepReport* total = nullptr,
                double tolerance_m = 1e-6) const {
    ModelOptions with = options;
    with.integrator.kind = kind;
    with.integrator.step_s = step_s;
    with.integrator.tolerance_m = tolerance_m;
    with.integrator.newton_tolerance_m = 1e-14;
    const SimModel model = build_model(mesh, with);
    SimState state = make_rest_state(model);
    for (std::size_t n = 0; n < mesh.node_count(); ++n) {
      const double s = mesh.rest_position_m.x[n] / kBarLength;
      state.position_m.y[n] += 1e-3 * s * s;  // 1 mm tip deflection
    }
    const StepReport report = advance(model, state, {}, duration_s);
    if (total) *total = report;
    return state.position_m;
  }
};

double max_distance_m(const NodeArray& a, const NodeArray& b) {
  double largest = 0.0;
  for (std::size_t n = 0; n < a.size(); ++n)
    largest = std::max(largest, (a.at(n) - b.at(n)).norm());
  return largest;
}

struct OrderCase {
  IntegratorKind kind;
  bool viscous;
};

class ConvergenceOrder : public ::testing::TestWithParam<OrderCase> {};

// Errors at Δt, Δt/2, Δt/4 against the same problem at Δt/64 with RK4. Observed order
// p = log2(e(Δt)/e(Δt/2)) tends to the scheme's order as Δt → 0; at these steps (ω_max·Δt ≤ 0.7
// for the stiffest mode) the next term of the error expansion moves it by less than 0.3.
TEST_P(ConvergenceOrder, MatchesTheSchemesOrder) {
  const auto [kind, viscous] = GetParam();
  const Cantilever bar(viscous ? fast_viscous_tissue() : elastic_tissue());
  const double duration = 0.05, coarse = 2e-4;
  const NodeArray reference = bar.run(IntegratorKind::rk4, coarse / 64, duration);
  double errors[3];
  for (int level = 0; level < 3; ++level) {
    StepReport report;
    const NodeArray result = bar.run(kind, coarse / (1 << level), duration, &report);
    ASSERT_EQ(report.stability_limited_steps, 0) << "the step must be the requested one";
    EXPECT_EQ(report.unconverged_steps, 0);
    errors[level] = max_distance_m(result, reference);
  }
  const int order = integrator_order(kind);
  for (int level = 0; level < 2; ++level) {
    const double measured = std::log2(errors[level] / errors[level + 1]);
    EXPECT_NEAR(measured, order, 0.3)
        << integrator_name(kind) << (viscous ? " viscous" : " elastic") << ": errors " << errors[0]
        << ", " << errors[1] << ", " << errors[2];
  }
}

INSTANTIATE_TEST_SUITE_P(Integrators, ConvergenceOrder,
                         ::testing::Values(OrderCase{IntegratorKind::central_difference, false},
                                           OrderCase{IntegratorKind::central_difference, true},
                                           OrderCase{IntegratorKind::rk4, false},
                                           OrderCase{IntegratorKind::rk4, true},
                                           OrderCase{IntegratorKind::backward_euler, false},
                                           OrderCase{IntegratorKind::backward_euler, true},
                                           OrderCase{IntegratorKind::bdf2, false},
                                           OrderCase{IntegratorKind::bdf2, true}),
                         [](const auto& info) {
                           std::string name(integrator_name(info.param.kind));
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name + (info.param.viscous ? "_viscous" : "_elastic");
                         });

// Error control: with the local error per step held near tol, the step scales like tol^(1/5) and
// the global error like tol·(steps) ∝ tol^(4/5), so two decades of tolerance must buy at least
// 100^(4/5)/2 ≈ 20. (Looser tolerances on this small bar are capped by the stability interval,
// which the test rules out.)
TEST(Dopri5, ErrorFollowsTheTolerance) {
  const Cantilever bar(fast_viscous_tissue());
  const double duration = 0.05;
  const NodeArray reference = bar.run(IntegratorKind::rk4, 2e-4 / 64, duration);
  StepReport loose_report, tight_report;
  const double loose = max_distance_m(
      bar.run(IntegratorKind::dopri5, 0.0, duration, &loose_report, 1e-9), reference);
  const double tight = max_distance_m(
      bar.run(IntegratorKind::dopri5, 0.0, duration, &tight_report, 1e-11), reference);
  EXPECT_EQ(loose_report.stability_limited_steps, 0);
  EXPECT_GT(loose / tight, 20.0) << loose << " vs " << tight;
  EXPECT_GT(tight_report.substeps, loose_report.substeps);
  EXPECT_LE(loose_report.error_estimate_m, 1e-9);  // accepted steps are within the tolerance
}

// Each scheme's own error estimate tracks the truth within an order of magnitude at a step in
// the asymptotic range (an estimate, not a bound: docs/integrators.md).
TEST(ErrorEstimate, IsReportedForEveryScheme) {
  const Cantilever bar(elastic_tissue());
  for (IntegratorKind kind : kAllIntegrators) {
    StepReport report;
    bar.run(kind, kind == IntegratorKind::dopri5 ? 0.0 : 1e-4, 0.01, &report);
    EXPECT_TRUE(std::isfinite(report.error_estimate_m)) << integrator_name(kind);
    EXPECT_GT(report.error_estimate_m, 0.0) << integrator_name(kind);
    EXPECT_GT(report.force_evaluations, report.substeps - 1) << integrator_name(kind);
    if (!is_explicit(kind)) {
      EXPECT_GT(report.linear_solves, 0);
      EXPECT_GT(report.factorizations, 0);
    }
  }
}

// A fixed-pace caller (the real-time loop) asks for intervals a little longer than the stable
// step. Covered exactly, each interval takes two steps; in whole steps (advance's whole_step_s),
// steps of the limit run on across the intervals, ending past each by less than one step: the
// evaluations are the time over the step, not twice the intervals.
TEST(WholeSteps, AnIntervalALittleOverTheLimitTakesOneStepNotTwo) {
  const Cantilever bar(elastic_tissue());
  const SimModel model = build_model(bar.mesh, bar.options);
  const double limit_s = model.stable_time_step_s, interval_s = 1.05 * limit_s;
  const int intervals = 200;
  auto run = [&](bool whole, double& lead_s) {
    SimState state = make_rest_state(model);
    for (std::size_t n = 0; n < bar.mesh.node_count(); ++n) {
      const double s = bar.mesh.rest_position_m.x[n] / kBarLength;
      state.position_m.y[n] += 1e-3 * s * s;
    }
    int evaluations = 0;
    lead_s = 0.0;
    for (int k = 0; k < intervals; ++k) {
      const double asked_s = interval_s - lead_s;
      const double before_s = state.time_s;
      if (asked_s > 0.0)
        evaluations +=
            advance(model, state, {}, asked_s, whole ? interval_s : 0.0).force_evaluations;
      lead_s = std::max(0.0, state.time_s - before_s - asked_s);
      EXPECT_LT(lead_s, limit_s * (1.0 + 1e-9));
      EXPECT_NEAR(state.time_s, (k + 1) * interval_s + lead_s, 1e-12);
    }
    return evaluations;
  };
  double lead_s = 0.0;
  EXPECT_EQ(run(false, lead_s), 2 * intervals);
  EXPECT_EQ(lead_s, 0.0);
  // At the limit (the step may not grow past it): ⌈200 × 1.05⌉ = 210 steps, give or take the
  // first, which kicks from rest.
  EXPECT_LE(run(true, lead_s), static_cast<int>(std::ceil(intervals * 1.05)) + 1);
}

// A caller asked to stop (the real-time loop, by SIGTERM) gives advance a flag: once it reads true,
// the interval ends where the step under way ends, what was done kept, however many steps were
// left.
TEST(GiveUp, AnAdvanceAskedToGiveUpEndsWithTheStepUnderWay) {
  const Cantilever bar(elastic_tissue());
  const SimModel model = build_model(bar.mesh, bar.options);
  SimState state = make_rest_state(model);
  std::atomic<bool> give_up{false};
  const StepReport whole = advance(model, state, {}, 0.01, 0.0, &give_up);
  EXPECT_FALSE(whole.gave_up_early);
  EXPECT_GT(whole.substeps, 1);
  EXPECT_DOUBLE_EQ(state.time_s, 0.01);
  give_up = true;
  const std::uint64_t steps_before = state.step_count;
  const StepReport none = advance(model, state, {}, 1000.0, 0.0, &give_up);
  EXPECT_TRUE(none.gave_up_early);
  EXPECT_EQ(none.substeps, 0);
  EXPECT_EQ(state.step_count, steps_before);
  EXPECT_DOUBLE_EQ(state.time_s, 0.01);
}

// A free bar pulled by equal and opposite end tractions: with the volumetric and deviatoric
// parts relaxing alike the 3-D response is the 1-D model, so the strain follows seed Eq. 3,
// ε(t) = σ/E2 + σ·(1/(E1+E2) − 1/E2)·exp(−t/τc). Mass damping α = 20/s removes the elastic
// transient of the sudden load (e^(−αt/2) < 5e-5 from t = 1 s) but makes the bar lag the
// quasi-static answer by δ ≈ α/ω₁² ≈ 2 ms (ω₁ ≈ 100 rad/s, its first stretching mode): a relative
// error δ·ε̇/ε ≤ 0.28/s·δ ≈ 6e-4 from t = 1 s; finite strain adds O(ε) = 3e-4, the integrator
// its error at its step.
TEST(Creep, EveryIntegratorFollowsSeedEquationThree) {
  const double e1 = 2000.0, e2 = 1500.0, tau = 0.5, sigma = 0.5;
  RegionMaterial material = elastic_tissue();
  material.viscoelastic = ViscoelasticParameters{e1, e2, e1 * tau};
  const TetMesh mesh = block_mesh(4, 1, 1, {kBarLength, kBarWidth, kBarWidth});
  const std::vector<PointLoad> loads = testing::end_face_tension(mesh, sigma);
  const double retardation = (e1 + e2) * tau / e2;
  for (IntegratorKind kind : kAllIntegrators) {
    ModelOptions options;
    options.regions[0] = material;
    options.mass_damping_per_s = 20.0;
    options.integrator.kind = kind;
    options.integrator.step_s = is_explicit(kind) ? 0.0 : 2e-3;
    const SimModel model = build_model(mesh, options);
    SimState state = make_rest_state(model);
    double worst = 0.0;
    for (int k = 1; k <= 40; ++k) {
      advance(model, state, StepInputs{loads, {}}, 0.1);
      if (k < 10) continue;
      const double t = 0.1 * k;
      const double strain =
          (testing::mean_coordinate_on_plane(mesh, state.position_m, 0, kBarLength) -
           testing::mean_coordinate_on_plane(mesh, state.position_m, 0, 0.0)) /
              kBarLength -
          1.0;
      const double expected =
          sigma / e2 + sigma * (1.0 / (e1 + e2) - 1.0 / e2) * std::exp(-t / retardation);
      worst = std::max(worst, std::abs(strain - expected) / expected);
    }
    EXPECT_LT(worst, 1e-3) << integrator_name(kind);
  }
}

// The seed's recipe (RK4 at Δt = 2 ms, ν = 0.49) is case 1 of the stability suite.

TEST(IntegratorSettings, InvalidSettingsAreRejectedWithTheirName) {
  const TetMesh mesh = block_mesh(1, 1, 1, {0.01, 0.01, 0.01});
  ModelOptions options;
  options.integrator.kind = IntegratorKind::backward_euler;
  options.integrator.step_s = 0.0;
  try {
    build_model(mesh, options);
    FAIL() << "an implicit scheme without a step was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("implicit"), std::string::npos) << error.what();
  }
  options.integrator.kind = IntegratorKind::dopri5;
  options.integrator.tolerance_m = std::nan("");
  EXPECT_THROW(build_model(mesh, options), std::invalid_argument);
  for (IntegratorKind kind : kAllIntegrators)
    EXPECT_EQ(integrator_from_name(integrator_name(kind)), kind);
  EXPECT_FALSE(integrator_from_name("euler"));
}

}  // namespace
}  // namespace liversim
