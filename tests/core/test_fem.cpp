#include "block_mesh.h"

#include "liversim/engine/forces.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"
#include "liversim/engine/surface.h"
#include "liversim/interaction/grab.h"
#include "liversim/meshing/liver_geometry.h"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace liversim {
namespace {

using testing::block_mesh;

double max_norm(const NodeArray& f, const std::vector<std::uint8_t>& select) {
  double m = 0.0;
  for (std::size_t n = 0; n < f.size(); ++n)
    if (select[n]) m = std::max(m, f.at(n).norm());
  return m;
}

// ---------------------------------------------------------------- constitutive law

TEST(NeoHookean, StressIsTheDerivativeOfTheEnergy) {
  const double mu = 1174.5, lambda = 57550.0;
  std::mt19937 random(3);
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  // Ordinary, strongly compressed (J below the Taylor switch) and inverted deformations.
  for (double squash : {1.0, 0.1, -0.3}) {
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    for (int i = 0; i < 9; ++i) F(i / 3, i % 3) += u(random);
    F.col(2) *= squash / F.determinant() * std::abs(F.determinant());
    const Eigen::Matrix3d P = neo_hookean::first_piola_stress(F, mu, lambda);
    ASSERT_TRUE(P.allFinite());
    for (int i = 0; i < 9; ++i) {
      const double h = 1e-6;
      Eigen::Matrix3d Fp = F, Fm = F;
      Fp(i / 3, i % 3) += h;
      Fm(i / 3, i % 3) -= h;
      const double numeric = (neo_hookean::energy_density(Fp, mu, lambda) -
                              neo_hookean::energy_density(Fm, mu, lambda)) /
                             (2 * h);
      // Central difference error is O(h²·Ψ''') ≪ 1e-4 of the stress scale λ here.
      EXPECT_NEAR(P(i / 3, i % 3), numeric, 1e-6 * lambda) << "J = " << F.determinant();
    }
  }
}

TEST(NeoHookean, RestIsStressFreeAndSmallStrainIsLinearElastic) {
  TissueMaterial tissue{3500.0, 0.49, 1060.0};
  const double mu = tissue.shear_modulus_pa(), lambda = tissue.lame_lambda_pa();
  EXPECT_LT(neo_hookean::first_piola_stress(Eigen::Matrix3d::Identity(), mu, lambda).norm(), 1e-12);
  // Small symmetric strain ε: σ = λ tr(ε) I + 2μ ε up to O(ε²).
  Eigen::Matrix3d eps;
  eps << 1.0, 0.3, -0.2, 0.3, -0.5, 0.1, -0.2, 0.1, 0.4;
  eps *= 1e-6;
  const Eigen::Matrix3d P =
      neo_hookean::first_piola_stress(Eigen::Matrix3d::Identity() + eps, mu, lambda);
  const Eigen::Matrix3d linear =
      lambda * eps.trace() * Eigen::Matrix3d::Identity() + 2.0 * mu * eps;
  EXPECT_LT((P - linear).norm(), 1e-4 * linear.norm());
}

TEST(NeoHookean, InvalidMaterialIsNamed) {
  auto message = validate(TissueMaterial{3500.0, 0.5, 1060.0});
  ASSERT_TRUE(message.has_value());
  EXPECT_NE(message->find("Poisson"), std::string::npos);
  message = validate(TissueMaterial{std::nan(""), 0.3, 1060.0});
  ASSERT_TRUE(message.has_value());
  EXPECT_NE(message->find("Young"), std::string::npos);
  EXPECT_FALSE(validate(TissueMaterial{}).has_value());
  ModelOptions bad;
  bad.regions[0].tissue.youngs_modulus_pa = -1.0;
  try {
    build_model(block_mesh(1, 1, 1, {0.01, 0.01, 0.01}), bad);
    ADD_FAILURE() << "a negative modulus was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("region 0"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------- patch tests

TEST(PatchTest, AffineDeformationLeavesInteriorNodesInEquilibrium) {
  const TetMesh mesh = block_mesh(4, 4, 4, {0.04, 0.04, 0.04}, 0.25);
  ModelOptions options;
  const SimModel model = build_model(mesh, options);
  Eigen::Matrix3d A;
  A << 1.10, 0.05, -0.02, 0.03, 0.92, 0.04, -0.01, 0.06, 1.05;  // finite strain, J > 0
  NodeArray x = mesh.rest_position_m;
  std::vector<std::uint8_t> interior(mesh.node_count()), boundary(mesh.node_count());
  for (std::size_t n = 0; n < mesh.node_count(); ++n) {
    x.set(n, A * mesh.rest_position_m.at(n) + Eigen::Vector3d(0.01, -0.02, 0.005));
    const Eigen::Vector3d r = mesh.rest_position_m.at(n) / 0.01;
    const bool on_box = r.minCoeff() < 1e-9 || r.maxCoeff() > 4 - 1e-9;
    boundary[n] = on_box;
    interior[n] = !on_box;
  }
  ForceScratch scratch = make_force_scratch(model);
  NodeArray force;
  force.resize(model.node_count);
  compute_elastic_forces(model, x, scratch, force);
  // Constant stress: interior contributions cancel to round-off, boundary ones do not.
  EXPECT_LT(max_norm(force, interior), 1e-10 * max_norm(force, boundary));
  EXPECT_GT(max_norm(force, boundary), 0.0);
}

TEST(PatchTest, InteriorRelaxesToTheAffineFieldWhenTheBoundaryIsPrescribed) {
  TetMesh mesh = block_mesh(3, 3, 3, {0.03, 0.03, 0.03}, 0.2);
  Eigen::Matrix3d A;
  A << 1.05, 0.02, 0.0, 0.0, 0.97, 0.03, 0.01, 0.0, 1.02;
  ModelOptions options;
  options.regions[0].tissue.poisson_ratio = 0.3;
  options.mass_damping_per_s = 60.0;
  std::vector<Eigen::Vector3d> expected(mesh.node_count());
  std::mt19937 random(11);
  std::uniform_real_distribution<double> perturb(-0.001, 0.001);
  for (std::size_t n = 0; n < mesh.node_count(); ++n) {
    expected[n] = A * mesh.rest_position_m.at(n);
    const Eigen::Vector3d r = mesh.rest_position_m.at(n) / 0.01;
    if (r.minCoeff() < 1e-9 || r.maxCoeff() > 3 - 1e-9)
      options.fixed_nodes.push_back(static_cast<NodeIndex>(n));
  }
  // Move the reference to the prescribed boundary positions by starting the state there.
  const SimModel model = build_model(mesh, options);
  SimState state = make_rest_state(model);
  for (std::size_t n = 0; n < mesh.node_count(); ++n)
    state.position_m.set(
        n, expected[n] + (model.is_fixed[n] ? Eigen::Vector3d::Zero()
                                            : Eigen::Vector3d(perturb(random), perturb(random),
                                                              perturb(random))));
  for (int i = 0; i < 400 && state.step_count < 200000; ++i) advance(model, state, {}, 0.01);
  double worst = 0.0;
  for (std::size_t n = 0; n < mesh.node_count(); ++n)
    worst = std::max(worst, (state.position_m.at(n) - expected[n]).norm());
  EXPECT_LT(worst, 1e-9);  // relaxed: the residual decays exponentially to round-off
}

// ---------------------------------------------------------------- static block vs analytic

TEST(StaticBlock, UniaxialTensionMatchesSmallStrainElasticity) {
  // A free bar pulled by equal and opposite uniform tractions on its end faces: the exact
  // small-strain answer is uniform uniaxial stress σ, axial strain σ/E, lateral strain −νσ/E.
  // Linear tetrahedra represent that linear field exactly, so the only error is geometric
  // nonlinearity, O(ε) relative: the tolerance is 5ε.
  const double length = 0.1, width = 0.02, sigma = 1.0;
  const TetMesh mesh = block_mesh(10, 2, 2, {length, width, width}, 0.15);
  ModelOptions options;
  options.regions[0].tissue = TissueMaterial{3500.0, 0.45, 1060.0};
  options.mass_damping_per_s = 120.0;
  const SimModel model = build_model(mesh, options);

  const std::vector<PointLoad> loads = testing::end_face_tension(mesh, sigma);
  SimState state = make_rest_state(model);
  const StepInputs inputs{loads, {}};
  // The free bar under dead loads keeps one soft mode, a slow rigid rotation that the loads
  // realign (decay rate ~ ω²/α ≈ 0.01/s); it leaves a residual near 1e-6 but changes no length.
  double residual = 1.0;
  for (int i = 0; i < 3000 && residual > 1e-6; ++i) {
    advance(model, state, inputs, 0.002);
    residual = 0.0;
    for (std::size_t n = 0; n < model.node_count; ++n)
      residual = std::max(residual, state.force_n.at(n).norm());
    residual /= sigma * width * width;
  }
  ASSERT_LT(residual, 1e-6);

  const double strain = sigma / options.regions[0].tissue.youngs_modulus_pa;
  const double elongation = testing::mean_coordinate_on_plane(mesh, state.position_m, 0, length) -
                            testing::mean_coordinate_on_plane(mesh, state.position_m, 0, 0.0);
  const double thinning = testing::mean_coordinate_on_plane(mesh, state.position_m, 1, width) -
                          testing::mean_coordinate_on_plane(mesh, state.position_m, 1, 0.0);
  EXPECT_NEAR(elongation / length - 1.0, strain, 5 * strain * strain);
  EXPECT_NEAR(thinning / width - 1.0, -options.regions[0].tissue.poisson_ratio * strain,
              5 * strain * strain);
}

// ---------------------------------------------------------------- stable step

// Dense M^(-1/2) K M^(-1/2) at rest from central differences of the force, for small meshes.
double exact_max_frequency(const SimModel& model) {
  const int n = static_cast<int>(model.node_count);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  ForceScratch scratch = make_force_scratch(model);
  NodeArray fp, fm;
  fp.resize(n);
  fm.resize(n);
  const double h = 1e-8;
  for (int j = 0; j < 3 * n; ++j) {
    if (model.is_fixed[j / 3]) continue;
    NodeArray x = model.rest_position_m;
    double* coordinate[3] = {&x.x[j / 3], &x.y[j / 3], &x.z[j / 3]};
    *coordinate[j % 3] += h;
    compute_elastic_forces(model, x, scratch, fp);
    *coordinate[j % 3] -= 2 * h;
    compute_elastic_forces(model, x, scratch, fm);
    for (int i = 0; i < 3 * n; ++i) {
      if (model.is_fixed[i / 3]) continue;
      const double fpi = i % 3 == 0 ? fp.x[i / 3] : i % 3 == 1 ? fp.y[i / 3] : fp.z[i / 3];
      const double fmi = i % 3 == 0 ? fm.x[i / 3] : i % 3 == 1 ? fm.y[i / 3] : fm.z[i / 3];
      A(i, j) = -(fpi - fmi) / (2 * h) /
                std::sqrt(model.lumped_mass_kg[i / 3] * model.lumped_mass_kg[j / 3]);
    }
  }
  A = 0.5 * (A + A.transpose());
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues().maxCoeff());
}

TEST(StableStep, PowerIterationFindsTheHighestFrequency) {
  ModelOptions options;
  options.fixed_nodes = {0, 1, 2, 3};
  const SimModel model = build_model(block_mesh(3, 2, 2, {0.03, 0.02, 0.02}, 0.2), options);
  const double exact = exact_max_frequency(model);
  // The Rayleigh quotient approaches from below; the step's safety factor (0.8) must cover the
  // gap, so the estimate has to be within 20 % and never above.
  EXPECT_LE(model.max_frequency_rad_per_s, exact * (1 + 1e-6));
  EXPECT_GE(model.max_frequency_rad_per_s, 0.95 * exact);
}

TEST(StableStep, CentralDifferenceBlowsUpJustAboveTheLimitAndNotBelow) {
  ModelOptions options;
  options.mass_damping_per_s = 0.0;
  options.fixed_nodes = {0, 1, 2, 3};
  const SimModel model = build_model(block_mesh(3, 2, 2, {0.03, 0.02, 0.02}, 0.2), options);
  const double limit = 2.0 / exact_max_frequency(model);
  auto energy_growth = [&](double dt) {
    SimState state = make_rest_state(model);
    std::mt19937 random(5);
    std::uniform_real_distribution<double> u(-1e-6, 1e-6);
    for (std::size_t n = 4; n < model.node_count; ++n)
      state.position_m.set(
          n, state.position_m.at(n) + Eigen::Vector3d(u(random), u(random), u(random)));
    const double e0 = strain_energy_j(model, state.position_m);
    for (int i = 0; i < 400; ++i) central_difference_step(model, state, {}, dt);
    return (strain_energy_j(model, state.position_m) +
            kinetic_energy_j(model, state.velocity_m_per_s)) /
           e0;
  };
  // Below the limit the energy stays within the leapfrog bound 1/(1 − (ωΔt/2)²) ≈ 10 of the
  // start; past it the highest mode grows by |r| ≈ 1.4 per step (r + 1/r = 2 − (ωΔt)²).
  EXPECT_LT(energy_growth(0.95 * limit), 1.0 / (1.0 - 0.95 * 0.95));
  EXPECT_FALSE(energy_growth(1.05 * limit) < 1e6);  // overflow to inf/NaN also counts
}

// ---------------------------------------------------------------- long runs on the liver

struct LiverFixture : ::testing::Test {
  static void SetUpTestSuite() { mesh_ = new TetMesh(generate_liver_mesh(3841).mesh); }
  static void TearDownTestSuite() { delete mesh_; }
  static TetMesh* mesh_;
};
TetMesh* LiverFixture::mesh_ = nullptr;

TEST_F(LiverFixture, UndampedFreeVibrationConservesTheLeapfrogEnergy) {
  ModelOptions options;
  options.fixed_nodes = mesh_->node_sets.at("ligament");
  options.mass_damping_per_s = 0.0;
  const SimModel model = build_model(*mesh_, options);
  SimState state = make_rest_state(model);
  // A smooth initial velocity field (low modes), small enough to stay near-linear.
  for (std::size_t n = 0; n < model.node_count; ++n)
    if (!model.is_fixed[n])
      state.velocity_m_per_s.y[n] = 0.002 * std::sin(20.0 * model.rest_position_m.x[n]);
  const double dt = model.stable_time_step_s;
  // Leapfrog exactly conserves ½ v⁻ᵀ M v⁺ + W(x) for linear elasticity; the neo-Hookean
  // nonlinearity perturbs it by O(ε) relative, with ε the largest strain seen.
  auto invariant = [&](const NodeArray& v_before) {
    double kinetic = 0.0;
    for (std::size_t n = 0; n < model.node_count; ++n)
      kinetic += 0.5 * model.lumped_mass_kg[n] * v_before.at(n).dot(state.velocity_m_per_s.at(n));
    return kinetic + strain_energy_j(model, state.position_m);
  };
  NodeArray v_before = state.velocity_m_per_s;
  central_difference_step(model, state, {}, dt);
  const double e0 = invariant(v_before);
  double worst_deviation = 0.0, max_strain = 0.0;
  for (int i = 1; i < 20000; ++i) {
    v_before = state.velocity_m_per_s;
    central_difference_step(model, state, {}, dt);
    if (i % 50 == 0) {
      worst_deviation = std::max(worst_deviation, std::abs(invariant(v_before) - e0) / e0);
      for (std::size_t e = 0; e < model.tet_count; e += 7)
        max_strain = std::max(max_strain, (deformation_gradient(model, state.position_m, e) -
                                           Eigen::Matrix3d::Identity())
                                              .norm());
    }
  }
  EXPECT_GT(state.time_s, 4.0);
  EXPECT_LT(worst_deviation, 10.0 * max_strain + 1e-9)
      << "strain " << max_strain << " simulated " << state.time_s << " s";
}

TEST_F(LiverFixture, EnergyDecaysAfterAPullIsReleased) {
  ModelOptions options;
  options.fixed_nodes = mesh_->node_sets.at("ligament");
  const SimModel model = build_model(*mesh_, options);
  SimState state = make_rest_state(model);
  const BoundarySurface surface = extract_surface(*mesh_);
  const Eigen::Vector3d point = mesh_->rest_position_m.at(surface.nodes[surface.nodes.size() / 2]);
  const Grab grab =
      grab_surface(surface, state.position_m, model.lumped_mass_kg, point, 0.015, 300.0);
  std::vector<NodeSpring> springs;
  grab_springs(grab, point + Eigen::Vector3d(0.0, 0.0, 0.04), springs);
  advance(model, state, StepInputs{{}, springs}, 0.5);

  // Free run: dE/dt = −α vᵀMv ≤ 0 exactly in continuous time, so the sampled energy may rise only
  // by the leapfrog's O((ωΔt)²) measurement error (< 1e-3 for this smooth motion).
  auto energy = [&] {
    return strain_energy_j(model, state.position_m) +
           kinetic_energy_j(model, state.velocity_m_per_s);
  };
  const double released = energy();
  ASSERT_GT(released, 0.0);
  double previous = released;
  for (int i = 0; i < 500; ++i) {
    advance(model, state, {}, 0.01);
    const double e = energy();
    ASSERT_TRUE(std::isfinite(e));
    EXPECT_LE(e, previous + 1e-3 * released) << "at t = " << state.time_s;
    previous = e;
  }
  // Every mode decays at least like e^(−αt) in energy; after 5 s that is e^(−40).
  EXPECT_LT(previous, 1e-6 * released);
}

TEST(Inversion, AnInvertedElementIsPushedBackOut) {
  const TetMesh mesh = testing::corner_tet_mesh(0.01);
  ModelOptions options;
  options.fixed_nodes = {0, 1, 2};
  options.mass_damping_per_s = 50.0;
  const SimModel model = build_model(mesh, options);
  SimState state = make_rest_state(model);
  state.position_m.set(3, {0.002, 0.002, -0.004});  // through the opposite face: J < 0
  ASSERT_LT(deformation_gradient(model, state.position_m, 0).determinant(), 0.0);
  for (int i = 0; i < 100; ++i) {
    advance(model, state, {}, 0.01);
    ASSERT_TRUE(state.position_m.at(3).allFinite());
  }
  EXPECT_NEAR(deformation_gradient(model, state.position_m, 0).determinant(), 1.0, 1e-6);
}

TEST(Model, RejectsBadMeshesAndFixedNodes) {
  TetMesh mesh = block_mesh(1, 1, 1, {0.01, 0.01, 0.01});
  ModelOptions options;
  options.fixed_nodes = {100};
  EXPECT_THROW(build_model(mesh, options), std::invalid_argument);
  TetMesh inverted = mesh;
  std::swap(inverted.corner[2][0], inverted.corner[3][0]);
  EXPECT_THROW(build_model(inverted, ModelOptions{}), std::invalid_argument);
  EXPECT_THROW(build_model(TetMesh{}, ModelOptions{}), std::invalid_argument);
}

// The plastic flow's interval is a time: negative, NaN or infinite is refused by name.
TEST(Model, RejectsAPlasticFlowIntervalThatIsNoTime) {
  const TetMesh mesh = block_mesh(1, 1, 1, {0.01, 0.01, 0.01});
  for (double bad : {-0.001, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    ModelOptions options;
    options.plastic_flow_interval_s = bad;
    try {
      build_model(mesh, options);
      ADD_FAILURE() << "an interval of " << bad << " s was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("plastic flow's interval"), std::string::npos)
          << e.what();
    }
  }
  ModelOptions every_step;
  every_step.plastic_flow_interval_s = 0.0;
  EXPECT_EQ(build_model(mesh, every_step).plastic_flow_interval_s, 0.0);
}

}  // namespace
}  // namespace liversim
