// The tangent ∂P/∂F of every energy equals the finite-difference derivative of its stress.
#include "block_mesh.h"

#include "liversim/engine/fibres.h"
#include "liversim/engine/forces.h"
#include "liversim/engine/material.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/viscous_tissue.h"

#include <gtest/gtest.h>

#include <functional>
#include <random>

namespace liversim {
namespace {

using Tangent = Eigen::Matrix<double, 9, 9>;

// Central differences of P along each F_kL; error O(h² P''') + O(ε P / h).
Tangent numeric_tangent(const std::function<Eigen::Matrix3d(const Eigen::Matrix3d&)>& stress,
                        const Eigen::Matrix3d& F) {
  Tangent t;
  const double h = 1e-6;
  for (int c = 0; c < 9; ++c) {
    Eigen::Matrix3d Fp = F, Fm = F;
    Fp(c / 3, c % 3) += h;
    Fm(c / 3, c % 3) -= h;
    const Eigen::Matrix3d dP = (stress(Fp) - stress(Fm)) / (2 * h);
    for (int r = 0; r < 9; ++r) t(r, c) = dP(r / 3, r % 3);
  }
  return t;
}

Eigen::Matrix3d random_deformation(std::mt19937& random, double volume_ratio) {
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 9; ++i) F(i / 3, i % 3) += u(random);
  F.col(2) *= volume_ratio / F.determinant();  // J = volume_ratio exactly
  return F;
}

TEST(Tangent, NeoHookeanIncludingCompressedAndInverted) {
  const TissueMaterial tissue;
  const double mu = tissue.shear_modulus_pa(), lambda = tissue.lame_lambda_pa();
  std::mt19937 random(23);
  for (double J : {1.0, 1.3, 0.6, 0.1, -0.4}) {
    const Eigen::Matrix3d F = random_deformation(random, J);
    const Tangent analytic = neo_hookean::stress_tangent(F, mu, lambda);
    const Tangent numeric = numeric_tangent(
        [&](const Eigen::Matrix3d& G) { return neo_hookean::first_piola_stress(G, mu, lambda); },
        F);
    EXPECT_LT((analytic - numeric).norm(), 1e-6 * analytic.norm()) << "J = " << J;
    EXPECT_LT((analytic - analytic.transpose()).norm(), 1e-9 * analytic.norm());  // hyperelastic
  }
}

TEST(Tangent, HgoFibreIncludingPastTheGuard) {
  std::mt19937 random(29);
  for (const FibreParameters p : {FibreParameters{800.0, 3.0}, FibreParameters{800.0, 300.0}}) {
    for (int trial = 0; trial < 10; ++trial) {
      const Eigen::Matrix3d F = random_deformation(random, 1.0) *
                                Eigen::Vector3d(1.4, 1.0, 1.0).asDiagonal();  // fibre in tension
      const Eigen::Vector3d a = Eigen::Vector3d(1.0, 0.2, -0.1).normalized();
      const Tangent analytic = hgo::stress_tangent(F, a, p);
      const Tangent numeric = numeric_tangent(
          [&](const Eigen::Matrix3d& G) { return hgo::first_piola_stress(G, a, p); }, F);
      EXPECT_LT((analytic - numeric).norm(), 1e-6 * (analytic.norm() + p.k1_pa));
    }
  }
}

TEST(Tangent, ElementWithTwoFibreFamiliesAndALesionRegion) {
  TetMesh mesh = testing::block_mesh(1, 1, 1, {0.01, 0.01, 0.01});
  mesh.region[3] = 1;
  ModelOptions options;
  options.regions[0].fibres = FibreParameters{600.0, 2.0};
  options.regions.push_back(
      {TissueMaterial{35000.0, 0.45, 1100.0}, std::nullopt, std::nullopt, std::nullopt});
  options.fibre_field.first_family = {Eigen::Vector3d(1, 1, 0)};
  options.fibre_field.second_family = {Eigen::Vector3d(1, -1, 0.3)};
  const SimModel model = build_model(mesh, options);
  std::mt19937 random(31);
  for (std::size_t e : {0u, 3u}) {
    const Eigen::Matrix3d F =
        random_deformation(random, 0.95) * Eigen::Vector3d(1.3, 1.1, 0.8).asDiagonal();
    const Tangent analytic = element_stress_tangent(model, e, F);
    const Tangent numeric = numeric_tangent(
        [&](const Eigen::Matrix3d& G) { return element_first_piola_stress(model, e, G); }, F);
    EXPECT_LT((analytic - numeric).norm(), 1e-6 * analytic.norm()) << "element " << e;
  }
}

// The viscous arm in rate form (for integrators that carry it) with a plastic deformation held:
// its tangent is the finite-difference derivative of its stress, for an explicit stage
// (keep 1, weight 0) and a backward-Euler step (keep 1/(1+θ), weight θ/(1+θ)), and below the
// collapse limit where the arm is frozen.
TEST(Tangent, ViscoelasticRateForm) {
  const ViscousTissueParameters parameters{kSeedViscoelastic, 0.45, std::nullopt};
  const ViscousTissueStep step(parameters, 0.0);
  std::mt19937 random(31);
  Eigen::Matrix3d fp_inverse = random_deformation(random, 1.0);  // isochoric
  const Voigt6 q{40.0, -25.0, 10.0, 5.0, -8.0, 12.0};
  const double theta = 0.4;
  // Not a structured binding: clang 14 cannot capture one in the lambda below.
  for (const std::pair<double, double>& arm :
       {std::pair{1.0, 0.0}, std::pair{1.0 / (1.0 + theta), theta / (1.0 + theta)}}) {
    const double keep = arm.first, weight = arm.second;
    for (double J : {1.0, 1.2, 0.7, 0.1}) {
      const Eigen::Matrix3d F = random_deformation(random, J);
      const Tangent analytic =
          viscoelastic_stress_tangent_rate_form(F, step, fp_inverse, q, keep, weight);
      const Tangent numeric = numeric_tangent(
          [&](const Eigen::Matrix3d& G) {
            Voigt6 elastic;
            return viscoelastic_stress_rate_form(G, step, fp_inverse, q, keep, weight, elastic);
          },
          F);
      EXPECT_LT((analytic - numeric).norm(), 1e-6 * analytic.norm())
          << "J = " << J << ", keep " << keep;
    }
  }
}

// The two forms of the arm describe one state: with Q = S_e − H, the rate form's stress at the
// committed deformation equals the incremental update's instantaneous (Δt = 0) stress.
TEST(ViscousRateForm, AgreesWithTheIncrementalUpdateOnOneState) {
  const ViscousTissueParameters parameters{kSeedViscoelastic, 0.45, std::nullopt};
  ViscousTissueState state;
  std::mt19937 random(37);
  const Eigen::Matrix3d F1 = random_deformation(random, 1.1), F2 = random_deformation(random, 0.9);
  viscous_tissue_update(F1, ViscousTissueStep(parameters, 0.0), state);  // load
  viscous_tissue_update(F2, ViscousTissueStep(parameters, 0.3), state);  // relax and move
  Voigt6 q, elastic;
  for (int k = 0; k < 6; ++k) q[k] = state.elastic_stress_pa[k] - state.maxwell_stress_pa[k];
  ViscousTissueState trial;
  const Eigen::Matrix3d incremental =
      viscous_tissue_stress(F2, ViscousTissueStep(parameters, 0.0), state, trial);
  const Eigen::Matrix3d rate_form =
      viscoelastic_stress_rate_form(F2, ViscousTissueStep(parameters, 0.0),
                                    state.inverse_plastic_deformation, q, 1.0, 0.0, elastic);
  EXPECT_LT((incremental - rate_form).norm(), 1e-12 * incremental.norm());
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(elastic[k], state.elastic_stress_pa[k], 1e-9);
}

}  // namespace
}  // namespace liversim
