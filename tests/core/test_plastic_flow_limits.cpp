// Where the viscoplastic flow stops (viscous_tissue.h): it never flows out more than the elastic
// strain there is, it holds at kMaxFlowStiffening, and the explicit step takes the stiffening a
// flow has given an element.
#include "block_mesh.h"

#include "liversim/engine/energy.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/state.h"
#include "liversim/engine/viscous_tissue.h"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <cmath>

namespace liversim {
namespace {

ViscousTissueParameters seed_tissue(double yield_limit_pa, double eta2_pa_s_pow_n) {
  return {kSeedViscoelastic, 0.49, ViscoplasticParameters{yield_limit_pa, eta2_pa_s_pow_n, 0.5}};
}

// Uniaxial isochoric stretch λ along x.
Eigen::Matrix3d uniaxial(double stretch) {
  const double lateral = 1.0 / std::sqrt(stretch);
  return Eigen::Vector3d(stretch, lateral, lateral).asDiagonal();
}

double largest_singular_value_squared(const Eigen::Matrix3d& m) {
  const double s = Eigen::JacobiSVD<Eigen::Matrix3d>(m).singularValues()(0);
  return s * s;
}

// A stretch of 3 held for 10⁴ s with almost no viscosity of flow: the closed-form increment by
// the step's modulus, (σ − σs)/(3G), would flow out 2.8 of Hencky strain where there is ln 3 = 1.1
// (the Neo-Hookean stress is 8.4·G there, not 3·G·ln 3) and leave the element compressed to
// 0.18 of its length: reversed. The flow takes out the share above yield of what there is.
TEST(PlasticFlow, NeverFlowsOutMoreThanTheElasticStrainThereIs) {
  const ViscousTissueStep step(seed_tissue(50.0, 0.1), 1e4);
  ViscousTissueState state;
  const Eigen::Matrix3d F = uniaxial(3.0);
  viscous_tissue_update(F, step, state);
  ASSERT_GT(state.equivalent_plastic_strain, 0.5);
  EXPECT_LE(state.equivalent_plastic_strain, std::log(3.0));
  const Eigen::Matrix3d elastic = F * state.inverse_plastic_deformation;
  EXPECT_GE(elastic(0, 0), 1.0);  // still stretched, not reversed
  EXPECT_LT(elastic(0, 0), 3.0);
}

// Held at a stretch of 6 (the seed's tissue, 10 ms steps), the flow stops once it has stiffened
// the element by kMaxFlowStiffening: in uniaxial tension σ_max(Fp⁻¹)² = exp(ε_p), so at a plastic
// strain of ln 4 (a plastic stretch of 4), however long it is held; the stored stiffening is
// σ_max(Fp⁻¹)².
TEST(PlasticFlow, StopsWhereItHasStiffenedTheElementByTheLimit) {
  const ViscousTissueStep step(seed_tissue(50.0, 2000.0), 0.01);
  ViscousTissueState state;
  const Eigen::Matrix3d F = uniaxial(6.0);
  int steps = 0;
  while (state.flow_stiffening < kMaxFlowStiffening && steps < 100000) {
    viscous_tissue_update(F, step, state);
    ++steps;
  }
  ASSERT_GE(state.flow_stiffening, kMaxFlowStiffening) << "after " << steps << " steps";
  EXPECT_LT(state.flow_stiffening, 1.05 * kMaxFlowStiffening);  // the last step's increment
  EXPECT_NEAR(state.flow_stiffening,
              largest_singular_value_squared(state.inverse_plastic_deformation),
              1e-9 * state.flow_stiffening);
  EXPECT_NEAR(std::log(state.flow_stiffening), state.equivalent_plastic_strain, 1e-6);
  const ViscousTissueState stopped = state;
  for (int k = 0; k < 1000; ++k) viscous_tissue_update(F, step, state);
  EXPECT_EQ(state.inverse_plastic_deformation, stopped.inverse_plastic_deformation);
  EXPECT_EQ(state.equivalent_plastic_strain, stopped.equivalent_plastic_strain);
}

// A block whose every element has flowed to half its length along x (Fp⁻¹ = diag(2, 1/√2, 1/√2),
// the stiffening 4, the yield too high to flow more) springs toward that shape and rings there,
// its elements half as thick along x. The explicit step takes the stiffening, and the scheme
// stays within the energy it was given.
TEST(PlasticFlow, TheExplicitStepTakesTheStiffeningOfAFlowedElement) {
  const TetMesh mesh = testing::block_mesh(4, 2, 2, {0.04, 0.02, 0.02});
  ModelOptions options;
  options.regions[0].viscoelastic = kSeedViscoelastic;
  options.regions[0].viscoplastic = ViscoplasticParameters{1e9, 2000.0, 0.5};
  const SimModel model = build_model(mesh, options);
  SimState state = make_rest_state(model);
  const StepReport at_rest = advance(model, state, {}, 0.01);
  EXPECT_LT(at_rest.max_stiffening, 1.01);
  EXPECT_EQ(at_rest.max_flow_stiffening, 1.0);

  state = make_rest_state(model);
  ViscousTissueState flowed;
  flowed.inverse_plastic_deformation =
      Eigen::Vector3d(2.0, 1.0 / std::sqrt(2.0), 1.0 / std::sqrt(2.0)).asDiagonal();
  flowed.flow_stiffening = largest_singular_value_squared(flowed.inverse_plastic_deformation);
  for (std::size_t e = 0; e < model.tet_count; ++e) state.viscous_history.store(e, flowed);
  EXPECT_EQ(state.viscous_history.largest_flow_stiffening(), 4.0);
  open_energy_books(model, state);
  const EnergyBalance start = energy_balance(model, state, {});
  const StepReport report = advance(model, state, {}, 0.5);
  EXPECT_GE(report.max_stiffening, 4.0);
  EXPECT_EQ(report.max_flow_stiffening, 4.0);  // and the report says it was the flow
  const EnergyBalance end = energy_balance(model, state, {});
  ASSERT_TRUE(std::isfinite(end.held_j()));
  EXPECT_LE(end.held_j(), start.supplied_j() * (1.0 + 1e-3));
}

// The report says which cause stiffened the mesh: a block compressed uniformly to 80 % of its
// length along x has J = 0.8 in every element at the first evaluation, and no flow.
TEST(PlasticFlow, TheStepReportSaysACompressionStiffenedTheMesh) {
  const TetMesh mesh = testing::block_mesh(4, 2, 2, {0.04, 0.02, 0.02});
  const SimModel model = build_model(mesh, ModelOptions{});
  SimState state = make_rest_state(model);
  for (std::size_t n = 0; n < model.node_count; ++n) state.position_m.x[n] *= 0.8;
  const StepReport report = advance(model, state, {}, 1e-4);
  EXPECT_NEAR(report.least_volume_ratio, 0.8, 1e-12);
  EXPECT_GT(report.max_stiffening, 1.0);
  EXPECT_EQ(report.max_flow_stiffening, 1.0);
}

}  // namespace
}  // namespace liversim
