#include "block_mesh.h"

#include "liversim/engine/fibres.h"
#include "liversim/engine/forces.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace liversim {
namespace {

using testing::block_mesh;

const Eigen::Vector3d kAlongX = Eigen::Vector3d::UnitX();

TEST(Fibres, StressIsTheDerivativeOfTheEnergyIncludingPastTheOverflowGuard) {
  std::mt19937 random(17);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  // Ordinary fibres, and very stiff ones stretched past the exponent guard (k2 (I4−1)² > 50).
  for (const FibreParameters p : {FibreParameters{500.0, 2.0}, FibreParameters{500.0, 200.0}}) {
    for (int trial = 0; trial < 20; ++trial) {
      Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
      for (int i = 0; i < 9; ++i) F(i / 3, i % 3) += u(random);
      const Eigen::Vector3d a = Eigen::Vector3d(u(random), u(random), 1.0).normalized();
      const Eigen::Matrix3d P = hgo::first_piola_stress(F, a, p);
      const double h = 1e-7;
      for (int i = 0; i < 9; ++i) {
        Eigen::Matrix3d Fp = F, Fm = F;
        Fp(i / 3, i % 3) += h;
        Fm(i / 3, i % 3) -= h;
        const double numeric =
            (hgo::energy_density(Fp, a, p) - hgo::energy_density(Fm, a, p)) / (2 * h);
        // Central differences: error O(h² Ψ''') plus round-off O(ε Ψ / h); relative 1e-5 covers
        // both even at exp(50).
        EXPECT_NEAR(P(i / 3, i % 3), numeric, 1e-5 * (std::abs(numeric) + p.k1_pa));
      }
      ASSERT_TRUE(P.allFinite());
    }
  }
}

TEST(Fibres, CarryNoLoadAtRestOrInCompression) {
  const FibreParameters p{800.0, 5.0};
  EXPECT_EQ(hgo::first_piola_stress(Eigen::Matrix3d::Identity(), kAlongX, p).norm(), 0.0);
  EXPECT_EQ(hgo::energy_density(Eigen::Matrix3d::Identity(), kAlongX, p), 0.0);
  const Eigen::Matrix3d shortened = Eigen::Vector3d(0.8, 1.1, 1.1).asDiagonal();
  EXPECT_EQ(hgo::first_piola_stress(shortened, kAlongX, p).norm(), 0.0);
  EXPECT_EQ(hgo::energy_density(shortened, kAlongX, p), 0.0);
}

TEST(Fibres, AreObjective) {
  const FibreParameters p{800.0, 5.0};
  Eigen::Matrix3d F;
  F << 1.3, 0.1, 0.0, 0.05, 0.9, 0.1, 0.0, -0.1, 1.05;
  const Eigen::Vector3d a = Eigen::Vector3d(1.0, 0.4, 0.2).normalized();
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  EXPECT_NEAR(hgo::energy_density(R * F, a, p), hgo::energy_density(F, a, p),
              1e-12 * hgo::energy_density(F, a, p));
  EXPECT_LT((hgo::first_piola_stress(R * F, a, p) - R * hgo::first_piola_stress(F, a, p)).norm(),
            1e-10);
}

TEST(Fibres, OverflowGuardKeepsHugeStretchFinite) {
  const FibreParameters p{1000.0, 1000.0};
  const Eigen::Matrix3d F = Eigen::Vector3d(3.0, 1.0, 1.0).asDiagonal();  // k2 (I4−1)² = 64000
  EXPECT_TRUE(std::isfinite(hgo::energy_density(F, kAlongX, p)));
  EXPECT_TRUE(hgo::first_piola_stress(F, kAlongX, p).allFinite());
  EXPECT_TRUE(std::isfinite(hgo::tangent_modulus_pa(F, kAlongX, p)));
}

// Uniaxial tension along x of a compressible Neo-Hookean + HGO solid, F = diag(λ, t, t): the
// lateral stress (1/J)(μ(t² − 1) + Λ ln J) vanishes for the lateral stretch t, and then σ11 =
// (1/J)(μ(λ² − 1) + Λ ln J + 2 k1 (λ² − 1) exp(k2 (λ² − 1)²) λ²) with the fibre along x.
struct UniaxialAnswer {
  double lateral_stretch;
  double axial_cauchy_stress_pa;
};

UniaxialAnswer analytic_uniaxial(double stretch, const TissueMaterial& tissue,
                                 const FibreParameters& along_x) {
  const double mu = tissue.shear_modulus_pa(), lambda = tissue.lame_lambda_pa();
  auto lateral = [&](double t) { return mu * (t * t - 1.0) + lambda * std::log(stretch * t * t); };
  double lo = 0.2, hi = 1.0;  // lateral(lo) < 0 < lateral(hi) for stretch > 1
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (lateral(mid) < 0.0 ? lo : hi) = mid;
  }
  const double t = 0.5 * (lo + hi), J = stretch * t * t, s = stretch * stretch - 1.0;
  const double fibre = 2.0 * along_x.k1_pa * s * std::exp(along_x.k2 * s * s) * stretch * stretch;
  return {t, (mu * s + lambda * std::log(J) + fibre) / J};
}

TEST(Fibres, UniaxialTensionAlongTheFibreMatchesTheAnalyticAnswer) {
  // The FEM kernel on an affinely stretched block: linear tetrahedra carry the homogeneous state
  // exactly, so interior nodes are in equilibrium and the end-face resultant divided by the current
  // area is σ11; the only error left is round-off (≤ 1e-6 relative).
  TissueMaterial tissue{3500.0, 0.49, 1060.0};
  const FibreParameters fibres{2000.0, 3.0};
  const TetMesh mesh = block_mesh(3, 2, 2, {0.03, 0.02, 0.02}, 0.2);
  ModelOptions options;
  options.regions[0] = {tissue, fibres, std::nullopt, std::nullopt};
  options.fibre_field.first_family = {kAlongX};
  const SimModel model = build_model(mesh, options);
  ASSERT_TRUE(model.effects.fibres);

  for (double stretch : {1.05, 1.2, 1.4}) {
    const UniaxialAnswer answer = analytic_uniaxial(stretch, tissue, fibres);
    NodeArray x = mesh.rest_position_m;
    const Eigen::Vector3d scale(stretch, answer.lateral_stretch, answer.lateral_stretch);
    for (std::size_t n = 0; n < x.size(); ++n) x.set(n, scale.cwiseProduct(x.at(n)));
    ForceScratch scratch = make_force_scratch(model);
    NodeArray force;
    force.resize(model.node_count);
    compute_elastic_forces(model, x, scratch, force);
    double end_force = 0.0;  // internal force on the x = L face nodes, pulling back
    for (std::size_t n = 0; n < x.size(); ++n)
      if (std::abs(mesh.rest_position_m.x[n] - 0.03) < 1e-12) end_force -= force.x[n];
    const double current_area = 0.02 * 0.02 * answer.lateral_stretch * answer.lateral_stretch;
    EXPECT_NEAR(end_force / current_area, answer.axial_cauchy_stress_pa,
                1e-6 * answer.axial_cauchy_stress_pa)
        << "stretch " << stretch;
    // The lateral faces carry no traction: the kernel's own lateral stress vanishes too.
    const Eigen::Matrix3d P = element_first_piola_stress(model, 0, scale.asDiagonal());
    EXPECT_LT(std::abs(P(1, 1)), 1e-6 * std::abs(P(0, 0)));
  }
}

TEST(Fibres, AcrossTheFibreTheResponseIsThePlainBaseMaterial) {
  TissueMaterial tissue{3500.0, 0.49, 1060.0};
  const TetMesh mesh = block_mesh(1, 1, 1, {0.01, 0.01, 0.01});
  ModelOptions with_fibres, without_fibres;
  with_fibres.regions[0] = {tissue, FibreParameters{2000.0, 3.0}, std::nullopt, std::nullopt};
  with_fibres.fibre_field.first_family = {Eigen::Vector3d::UnitY()};
  without_fibres.regions[0] = {tissue, std::nullopt, std::nullopt, std::nullopt};
  const SimModel a = build_model(mesh, with_fibres), b = build_model(mesh, without_fibres);
  // Stretched along x: the y fibres shorten (I4 = t² < 1) and switch off.
  const UniaxialAnswer answer = analytic_uniaxial(1.3, tissue, FibreParameters{});
  const Eigen::Matrix3d F =
      Eigen::Vector3d(1.3, answer.lateral_stretch, answer.lateral_stretch).asDiagonal();
  EXPECT_EQ((element_first_piola_stress(a, 0, F) - element_first_piola_stress(b, 0, F)).norm(),
            0.0);
  // Stretched along y, the fibres engage and the response is stiffer.
  const Eigen::Matrix3d G =
      Eigen::Vector3d(answer.lateral_stretch, 1.3, answer.lateral_stretch).asDiagonal();
  EXPECT_GT(element_first_piola_stress(a, 0, G)(1, 1), element_first_piola_stress(b, 0, G)(1, 1));
}

TEST(Fibres, TwoFamiliesAddUp) {
  const TetMesh mesh = block_mesh(1, 1, 1, {0.01, 0.01, 0.01});
  const FibreParameters p{1000.0, 2.0};
  ModelOptions one, two;
  one.regions[0].fibres = p;
  one.fibre_field.first_family = {Eigen::Vector3d(1, 1, 0)};
  two.regions[0].fibres = p;
  two.fibre_field.first_family = {Eigen::Vector3d(1, 1, 0)};
  two.fibre_field.second_family = {Eigen::Vector3d(1, -1, 0)};
  const SimModel a = build_model(mesh, one), b = build_model(mesh, two);
  const Eigen::Matrix3d F = Eigen::Vector3d(1.2, 1.0, 1.0).asDiagonal();
  const Eigen::Matrix3d expected =
      element_first_piola_stress(a, 0, F) +
      hgo::first_piola_stress(F, Eigen::Vector3d(1, -1, 0).normalized(), p);
  EXPECT_LT((element_first_piola_stress(b, 0, F) - expected).norm(), 1e-9 * expected.norm());
}

TEST(Fibres, BadFibreSettingsAreNamed) {
  const TetMesh mesh = block_mesh(1, 1, 1, {0.01, 0.01, 0.01});  // 6 elements
  ModelOptions options;
  options.regions[0].fibres = FibreParameters{1000.0, 2.0};
  auto message_of = [&](const ModelOptions& o) {
    try {
      build_model(mesh, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message_of(options).find("no direction"), std::string::npos);
  options.fibre_field.first_family = {kAlongX, kAlongX};
  EXPECT_NE(message_of(options).find("expected 1 or 6"), std::string::npos);
  options.fibre_field.first_family = {Eigen::Vector3d::Zero()};
  EXPECT_NE(message_of(options).find("zero or not a number"), std::string::npos);
  options.fibre_field.first_family = {kAlongX};
  options.regions[0].fibres = FibreParameters{std::nan(""), 2.0};
  EXPECT_NE(message_of(options).find("k1"), std::string::npos);
}

TEST(Fibres, StronglyStiffeningFibresShortenTheStepAndStayStable) {
  // Released from λ = 1.6 along stiffening fibres (k2 = 2: exp(2·1.56²) ≈ 130), whose tangent is
  // then ~100× the matrix's: the step must shrink by ~10 and the run must stay finite.
  const TetMesh mesh = block_mesh(3, 2, 2, {0.03, 0.02, 0.02}, 0.2);
  ModelOptions options;
  options.regions[0].fibres = FibreParameters{500.0, 2.0};
  options.fibre_field.first_family = {kAlongX};
  options.fixed_nodes = {0};
  const SimModel model = build_model(mesh, options);
  SimState state = make_rest_state(model);
  for (std::size_t n = 0; n < model.node_count; ++n) state.position_m.x[n] *= 1.6;
  const StepReport report = advance(model, state, {}, 0.05);
  EXPECT_GT(report.max_stiffening, 100.0);
  EXPECT_LT(report.smallest_substep_s, model.stable_time_step_s / 5.0);
  for (std::size_t n = 0; n < model.node_count; ++n)
    ASSERT_TRUE(state.position_m.at(n).allFinite());
  // Energy after the run is below the stretched start: nothing was pumped in.
  NodeArray start = model.rest_position_m;
  for (std::size_t n = 0; n < model.node_count; ++n) start.x[n] *= 1.6;
  EXPECT_LT(
      strain_energy_j(model, state.position_m) + kinetic_energy_j(model, state.velocity_m_per_s),
      strain_energy_j(model, start));
}

TEST(Regions, AStiffLesionDeformsTenTimesLessUnderTheSameStress) {
  // A bar of two halves in series, the far half a lesion 10× stiffer, pulled by end tractions.
  // With ν = 0 the halves do not constrain each other laterally, the stress is the same uniaxial
  // σ in both, and the small-strain elongations differ by exactly E_lesion/E_tissue = 10; geometric
  // nonlinearity adds O(ε) relative.
  const double length = 0.04, width = 0.01, sigma = 0.5;
  TetMesh mesh = block_mesh(8, 2, 2, {length, width, width});
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    double centroid_x = 0.0;
    for (auto n : mesh.tet(e)) centroid_x += 0.25 * mesh.rest_position_m.x[n];
    mesh.region[e] = centroid_x > 0.5 * length ? 1 : 0;
  }
  ModelOptions options;
  options.regions[0].tissue = TissueMaterial{3500.0, 0.0, 1060.0};
  options.regions.push_back(
      {TissueMaterial{35000.0, 0.0, 1060.0}, std::nullopt, std::nullopt, std::nullopt});
  options.mass_damping_per_s = 150.0;
  const SimModel model = build_model(mesh, options);
  const std::vector<PointLoad> loads = testing::end_face_tension(mesh, sigma);
  SimState state = make_rest_state(model);
  for (int i = 0; i < 400; ++i) advance(model, state, StepInputs{loads, {}}, 0.01);
  auto mean_x_at = [&](double rest_x) {
    return testing::mean_coordinate_on_plane(mesh, state.position_m, 0, rest_x);
  };
  const double soft = mean_x_at(0.5 * length) - mean_x_at(0.0) - 0.5 * length;
  const double stiff = mean_x_at(length) - mean_x_at(0.5 * length) - 0.5 * length;
  const double strain = sigma / 3500.0;
  EXPECT_NEAR(soft / (0.5 * length), strain, 5 * strain * strain);
  EXPECT_NEAR(soft / stiff, 10.0, 10.0 * 5 * strain);
}

}  // namespace
}  // namespace liversim
