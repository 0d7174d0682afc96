// The Mooney–Rivlin option and the objectivity of every energy.
#include "block_mesh.h"

#include "liversim/engine/fibres.h"
#include "liversim/engine/forces.h"
#include "liversim/engine/material.h"
#include "liversim/engine/model_building.h"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <random>

namespace liversim {
namespace {

SimModel one_element_model(const TissueMaterial& tissue, bool fibres = false) {
  ModelOptions options;
  options.regions[0].tissue = tissue;
  if (fibres) {
    options.regions[0].fibres = FibreParameters{700.0, 2.0};
    options.fibre_field.first_family = {Eigen::Vector3d(1.0, 0.3, 0.1)};
  }
  return build_model(testing::block_mesh(1, 1, 1, {0.01, 0.01, 0.01}), options);
}

Eigen::Matrix3d random_deformation(std::mt19937& random, double volume_ratio) {
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 9; ++i) F(i / 3, i % 3) += u(random);
  F.col(2) *= volume_ratio / F.determinant();
  return F;
}

TEST(MooneyRivlin, StressAndTangentAreDerivativesIncludingCompressedAndInverted) {
  const SimModel model = one_element_model(TissueMaterial{3500.0, 0.45, 1060.0, 0.4});
  ASSERT_TRUE(model.effects.mooney_rivlin);
  std::mt19937 random(41);
  for (double J : {1.0, 1.2, 0.5, 0.1, -0.3}) {
    const Eigen::Matrix3d F = random_deformation(random, J);
    const Eigen::Matrix3d P = element_first_piola_stress(model, 0, F);
    const Eigen::Matrix<double, 9, 9> A = element_stress_tangent(model, 0, F);
    const double h = 1e-6;
    for (int c = 0; c < 9; ++c) {
      Eigen::Matrix3d Fp = F, Fm = F;
      Fp(c / 3, c % 3) += h;
      Fm(c / 3, c % 3) -= h;
      // Central differences: O(h²) truncation, far below the 1e-6 relative tolerance.
      const double dpsi =
          (element_energy_density(model, 0, Fp) - element_energy_density(model, 0, Fm)) / (2 * h);
      EXPECT_NEAR(P(c / 3, c % 3), dpsi, 1e-6 * P.norm() + 1e-6) << "J = " << J;
      const Eigen::Matrix3d dP =
          (element_first_piola_stress(model, 0, Fp) - element_first_piola_stress(model, 0, Fm)) /
          (2 * h);
      for (int r = 0; r < 9; ++r)
        EXPECT_NEAR(A(r, c), dP(r / 3, r % 3), 1e-6 * A.norm()) << "J = " << J;
    }
  }
}

TEST(MooneyRivlin, RestIsStressFreeWithTheSameSmallStrainModuliAsNeoHookean) {
  const TissueMaterial neo{3500.0, 0.49, 1060.0, 0.0}, mooney{3500.0, 0.49, 1060.0, 0.6};
  const SimModel a = one_element_model(neo), b = one_element_model(mooney);
  EXPECT_LT(element_first_piola_stress(b, 0, Eigen::Matrix3d::Identity()).norm(), 1e-9);
  // Linearised at rest both are the same isotropic elastic solid (μ = 2(c1 + c2), same λ).
  const auto ta = element_stress_tangent(a, 0, Eigen::Matrix3d::Identity());
  const auto tb = element_stress_tangent(b, 0, Eigen::Matrix3d::Identity());
  EXPECT_LT((ta - tb).norm(), 1e-9 * ta.norm());
  // At finite strain they differ: simple shear of 0.5.
  Eigen::Matrix3d shear = Eigen::Matrix3d::Identity();
  shear(0, 1) = 0.5;
  EXPECT_GT(
      (element_first_piola_stress(a, 0, shear) - element_first_piola_stress(b, 0, shear)).norm(),
      1e-3 * element_first_piola_stress(a, 0, shear).norm());
}

TEST(MooneyRivlin, FractionOutsideItsRangeIsNamed) {
  ModelOptions options;
  options.regions[0].tissue.mooney_rivlin_fraction = 1.2;
  try {
    build_model(testing::block_mesh(1, 1, 1, {0.01, 0.01, 0.01}), options);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("Mooney-Rivlin fraction"), std::string::npos);
  }
}

TEST(Objectivity, EveryEnergyIsInvariantAndEveryStressRotates) {
  // Ψ(RF) = Ψ(F) and P(RF) = R P(F) for a rigid rotation R after the deformation, including
  // compressed states below the Taylor switch.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, 1.0, -0.4).normalized()).toRotationMatrix();
  std::mt19937 random(43);
  for (const SimModel& model :
       {one_element_model(TissueMaterial{}), one_element_model(TissueMaterial{}, true),
        one_element_model(TissueMaterial{3500.0, 0.45, 1060.0, 0.5}, true)}) {
    for (double J : {1.0, 1.3, 0.15}) {
      const Eigen::Matrix3d F = random_deformation(random, J);
      const double psi = element_energy_density(model, 0, F);
      EXPECT_NEAR(element_energy_density(model, 0, R * F), psi, 1e-10 * std::abs(psi) + 1e-12);
      const Eigen::Matrix3d P = element_first_piola_stress(model, 0, F);
      EXPECT_LT((element_first_piola_stress(model, 0, R * F) - R * P).norm(), 1e-10 * P.norm());
    }
  }
}

}  // namespace
}  // namespace liversim
