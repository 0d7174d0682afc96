// Material-point verification of the viscoelastic-viscoplastic tissue law against the seed's 1-D
// formulas (Eq. 2, 3, 4). Measured errors are recorded as test properties: run with
// --gtest_output=xml:FILE to see them (docs/viscous-tissue.md quotes them).
//
// Why the 1-D formulas are the exact small-strain answer of the 3-D law: shear and bulk response
// relax by the same factor φ(t) = g0 + g1·exp(−t/τ), so the stress is φ convolved with an elastic
// stress C:ε. Zero lateral stress for all t then forces C:ε to be uniaxial for all t (the
// convolution with φ, φ(0) ≠ 0, is invertible), so the lateral strain stays −ν·ε at every instant
// and the axial stress is φ convolved with (E1 + E2)·ε: the 1-D standard linear solid. The
// remaining differences are geometric, of relative order ε.

#include "liversim/engine/viscous_tissue.h"

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

namespace liversim {
namespace {

// A liver-like split of the seed's E = 3500 Pa (E1 + E2) with τ = 1 s, τc = 7/3 s.
constexpr double kE1 = 2000.0, kE2 = 1500.0, kEta1 = 2000.0, kNu = 0.49;
constexpr double kE0 = kE1 + kE2;
constexpr double kTau = kEta1 / kE1;
constexpr double kTauC = kE0 * kTau / kE2;

ViscousTissueParameters viscoelastic_tissue() {
  return {{kE1, kE2, kEta1}, kNu, std::nullopt};
}

ViscousTissueParameters viscoplastic_tissue(double yield_pa, double eta2, double n) {
  return {{kE1, kE2, kEta1}, kNu, ViscoplasticParameters{yield_pa, eta2, n}};
}

std::string scientific(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3e", value);
  return text;
}

// Eq. 3: creep strain of the standard linear solid at held stress σ.
double sls_creep_strain(double stress_pa, double t_s) {
  return stress_pa / kE2 + stress_pa * (1.0 / kE0 - 1.0 / kE2) * std::exp(-t_s / kTauC);
}

// Worst relative error of the relaxation curve against Eq. 2 over 5τ after a step strain, and the
// largest drift of the lateral stretch from its value just after the step.
struct RelaxationErrors {
  double stress, lateral_drift;
};

RelaxationErrors relaxation_error(double strain, double dt_s) {
  UniaxialDriver driver(viscoelastic_tissue());
  driver.step_to_stretch(1.0 + strain, 0.0);
  const double lateral = driver.lateral_stretch();
  RelaxationErrors worst{0.0, 0.0};
  const int steps = static_cast<int>(std::lround(5.0 * kTau / dt_s));
  for (int k = 1; k <= steps; ++k) {
    const double stress = driver.step_to_stretch(1.0 + strain, dt_s);
    const double sigma0 = kE0 * strain;
    const double exact = kE2 * strain + (sigma0 - kE2 * strain) * std::exp(-k * dt_s / kTau);
    worst.stress = std::max(worst.stress, std::abs(stress / exact - 1.0));
    worst.lateral_drift =
        std::max(worst.lateral_drift, std::abs(driver.lateral_stretch() - lateral));
  }
  return worst;
}

// Worst relative error of the axial strain against Eq. 4 (Eq. 3 when there is no yield) under a
// held nominal stress applied at t = 0, over 5τc.
double creep_error(const ViscousTissueParameters& tissue, double stress_pa, double dt_s) {
  UniaxialDriver driver(tissue);
  driver.step_to_nominal_stress(stress_pa, 0.0);
  double worst = 0.0;
  const int steps = static_cast<int>(std::lround(5.0 * kTauC / dt_s));
  for (int k = 1; k <= steps; ++k) {
    const double t = k * dt_s;
    const double strain = driver.step_to_nominal_stress(stress_pa, dt_s) - 1.0;
    double exact = sls_creep_strain(stress_pa, t);
    if (const auto& vp = tissue.viscoplastic)
      exact += std::max(stress_pa - vp->yield_limit_pa, 0.0) * std::pow(t, vp->creep_index_n) /
               vp->eta2_pa_s_pow_n;
    worst = std::max(worst, std::abs(strain / exact - 1.0));
  }
  return worst;
}

// ---------------------------------------------------------------- seed Eq. 2, 3, 4

TEST(ViscousTissue, RelaxationAtHeldStrainFollowsEq2) {
  // After the step the elastic stress S_e is constant, and the exponential update is exact for
  // an S_e piecewise linear in time: the lateral stretch stays put (S = φ(t)·S_e keeps S_yy = 0)
  // and S_xx = φ(t)·S_e,xx exactly. The only error is the Neo-Hookean P_xx against (E1+E2)·ε,
  // of relative order ε (≈ 1.0·ε here): the same at Δt and Δt/2, ten times smaller at ε/10.
  const RelaxationErrors coarse = relaxation_error(1e-4, kTau / 20.0);
  const RelaxationErrors fine = relaxation_error(1e-4, kTau / 40.0);
  const RelaxationErrors small_strain = relaxation_error(1e-5, kTau / 20.0);
  RecordProperty("error_dt_tau_over_20", scientific(coarse.stress));
  RecordProperty("error_dt_tau_over_40", scientific(fine.stress));
  RecordProperty("error_strain_1e-5", scientific(small_strain.stress));
  RecordProperty("lateral_stretch_drift", scientific(coarse.lateral_drift));
  EXPECT_LE(coarse.stress, 1e-3);
  EXPECT_NEAR(fine.stress, coarse.stress, 1e-9);
  EXPECT_NEAR(small_strain.stress / coarse.stress, 0.1, 0.01);
  // Newton starts from the previous lateral stretch, where the residual is round-off (1e-13 Pa
  // against a stiffness of 6e4 Pa): it does not move by more than a few ulps.
  EXPECT_LE(coarse.lateral_drift, 1e-15);
}

TEST(ViscousTissue, CreepAtHeldStressFollowsEq3) {
  // Under creep S_e is not linear in time within a step, so the update adds an O(Δt²) global
  // error to the geometric O(ε) one (≈ 1.2e-4 at ε ≈ 1e-4). At ε ≈ 1e-7 the geometric part is
  // ≈ 1e-7 and the time error shows alone: halving Δt must divide it by 4.
  const double stress_pa = 0.175;  // ε from 5e-5 (instantaneous) to 1.17e-4 (relaxed)
  const double error = creep_error(viscoelastic_tissue(), stress_pa, kTau / 20.0);
  const double tiny_coarse = creep_error(viscoelastic_tissue(), 1e-3 * stress_pa, kTau / 10.0);
  const double tiny_fine = creep_error(viscoelastic_tissue(), 1e-3 * stress_pa, kTau / 20.0);
  const double order = std::log2(tiny_coarse / tiny_fine);
  RecordProperty("error_dt_tau_over_20", scientific(error));
  RecordProperty("error_strain_1e-7_dt_tau_over_10", scientific(tiny_coarse));
  RecordProperty("error_strain_1e-7_dt_tau_over_20", scientific(tiny_fine));
  EXPECT_LE(error, 1e-3);
  EXPECT_NEAR(order, 2.0, 0.1);
}

TEST(ViscousTissue, CreepAboveYieldFollowsEq4) {
  // Under uniaxial stress the Kirchhoff deviator is (2/3, −1/3, −1/3)·σ, so σ_eq = |σ| and the
  // flow direction N = (3/2)·s/σ_eq = diag(1, −1/2, −1/2): the axial plastic strain rate equals
  // the equivalent one, and the 1-D Eq. 4 applies with σ_eq = σ. Increments of tⁿ make the plastic
  // part exact for any Δt under a held stress, including the first step at yield onset for
  // n = 0.5 (Δ(tⁿ) = Δtⁿ, finite). What remains: the O(Δt²) of the viscoelastic part and the
  // geometric O(ε), amplified to ≈ 3e-4 by σ/(σ − σs) in the plastic part because σ_eq is the
  // Kirchhoff stress τ_xx = λ·P_xx while the driver holds the nominal P_xx. At 1e-3 of the stress
  // (ε ≈ 1e-7) the time error shows alone, of order 2.
  const double stress_pa = 0.175, yield_pa = 0.075;
  for (double n : {1.0, 0.5}) {
    // η2 such that the plastic strain after 5τc is about 1e-4, like the viscoelastic one.
    const double eta2 = (stress_pa - yield_pa) * std::pow(5.0 * kTauC, n) / 1e-4;
    const double error =
        creep_error(viscoplastic_tissue(yield_pa, eta2, n), stress_pa, kTau / 20.0);
    const auto tiny = viscoplastic_tissue(1e-3 * yield_pa, eta2, n);
    const double tiny_coarse = creep_error(tiny, 1e-3 * stress_pa, kTau / 10.0);
    const double tiny_fine = creep_error(tiny, 1e-3 * stress_pa, kTau / 20.0);
    const std::string label = n == 1.0 ? "n_1" : "n_0_5";
    RecordProperty(label + "_error_dt_tau_over_20", scientific(error));
    RecordProperty(label + "_error_strain_1e-7_dt_tau_over_10", scientific(tiny_coarse));
    RecordProperty(label + "_error_strain_1e-7_dt_tau_over_20", scientific(tiny_fine));
    EXPECT_LE(error, 1e-3) << "n = " << n;
    EXPECT_NEAR(std::log2(tiny_coarse / tiny_fine), 2.0, 0.1) << "n = " << n;
  }
}

// Holds a nominal stress for `steps` steps of dt_s after an instantaneous jump to it.
void hold_stress(UniaxialDriver& driver, double stress_pa, int steps, double dt_s) {
  driver.step_to_nominal_stress(stress_pa, 0.0);
  for (int k = 0; k < steps; ++k) driver.step_to_nominal_stress(stress_pa, dt_s);
}

TEST(ViscousTissue, ViscoplasticStrainIsPermanent) {
  // Load for T = 2τc, unload to zero stress, wait. The standard linear solid recovers all but
  // σ·(1/E2 − 1/E0)·(1 − e^(−T/τc))·e^(−w/τc) of its strain after a wait w: 2.6e-9 for σ = 0.175
  // Pa at w = 10τc, 1.0e-9 for σ = 0.07 Pa at 10τc but 4.8e-14 at 20τc. So at 10τc the residual
  // strain of a cycle above yield is the plastic strain exp(ε_p) − 1 to 2.6e-5 relative, and at
  // 20τc the residual of a cycle below yield is that 4.8e-14 (plus round-off: Newton resolves the
  // stretch to |Δλ| ≤ 1e-14), far below 1e-9. Waiting only 10τc would leave it at the 1e-9 bound.
  const double yield_pa = 0.075, n = 0.5, dt_s = kTauC / 50.0, hold_s = 100 * dt_s;
  const double eta2 = 0.1 * std::pow(hold_s, n) / 1e-4;
  auto residual_strain = [&](double stress_pa, int wait_steps, double& plastic_strain) {
    UniaxialDriver driver(viscoplastic_tissue(yield_pa, eta2, n));
    hold_stress(driver, stress_pa, 100, dt_s);
    hold_stress(driver, 0.0, wait_steps, 4.0 * dt_s);
    plastic_strain = driver.state().equivalent_plastic_strain;
    return driver.axial_stretch() - 1.0;
  };

  double plastic = 0.0;
  const double residual_above = residual_strain(0.175, 125, plastic);  // 10τc
  const double eq4_plastic = (0.175 - yield_pa) * std::pow(hold_s, n) / eta2;
  RecordProperty("residual_above_yield", scientific(residual_above));
  RecordProperty("relative_to_plastic_strain",
                 scientific(std::abs(residual_above / std::expm1(plastic) - 1.0)));
  RecordProperty("plastic_relative_to_eq4", scientific(std::abs(plastic / eq4_plastic - 1.0)));
  EXPECT_GT(residual_above, 0.5e-4);
  EXPECT_NEAR(residual_above / std::expm1(plastic), 1.0, 1e-3);
  EXPECT_NEAR(plastic / eq4_plastic, 1.0, 1e-3);  // the geometric O(ε·σ/(σ − σs)) of Eq. 4

  double no_plastic = 1.0;
  const double residual_below = residual_strain(0.07, 250, no_plastic);  // 20τc
  RecordProperty("residual_below_yield", scientific(residual_below));
  EXPECT_EQ(no_plastic, 0.0);
  EXPECT_LT(std::abs(residual_below), 1e-9);
}

TEST(ViscousTissue, YieldClockHoldsWhileUnloaded) {
  // Time hardening with a clock that counts only the time above yield: two holds of T at the
  // same stress separated by an unloaded rest give (σ − σs)·(2T)ⁿ/η2, not the 2·Tⁿ a reset clock
  // would give (a factor √2 apart at n = 0.5). The tolerance is the geometric O(ε·σ/(σ − σs)).
  const double stress_pa = 0.175, yield_pa = 0.075, n = 0.5, dt_s = kTauC / 50.0;
  const double hold_s = 50 * dt_s;
  const double eta2 = (stress_pa - yield_pa) * std::pow(2.0 * hold_s, n) / 1e-4;
  UniaxialDriver driver(viscoplastic_tissue(yield_pa, eta2, n));
  hold_stress(driver, stress_pa, 50, dt_s);
  hold_stress(driver, 0.0, 250, dt_s);
  EXPECT_NEAR(driver.state().yield_clock_s, hold_s, 1e-12);
  hold_stress(driver, stress_pa, 50, dt_s);
  const double expected = (stress_pa - yield_pa) * std::pow(2.0 * hold_s, n) / eta2;
  RecordProperty("relative_to_continued_clock",
                 scientific(std::abs(driver.state().equivalent_plastic_strain / expected - 1.0)));
  EXPECT_NEAR(driver.state().equivalent_plastic_strain / expected, 1.0, 1e-3);
}

// ---------------------------------------------------------------- any step length

TEST(ViscousTissue, StableAndRelaxedForAnyStepLength) {
  const double strain = 1e-4;
  double worst_relaxed = 0.0, worst_plastic = 0.0, worst_eq4 = 0.0;
  UniaxialDriver instant(viscoelastic_tissue());
  const double instantaneous_pa = instant.step_to_stretch(1.0 + strain, 0.0);
  const double g0 = kE2 / kE0, g1 = kE1 / kE0;
  for (double dt_over_tau : {10.0, 100.0, 1e4}) {
    // Held strain: H decays by exactly g = exp(−Δt/τ) per step, so after k steps
    // P = (g0 + g1·g^k)·P_instantaneous: never above the elastic trial, the relaxed value at once.
    UniaxialDriver driver(viscoelastic_tissue());
    driver.step_to_stretch(1.0 + strain, 0.0);
    for (int k = 1; k <= 3; ++k) {
      const double stress = driver.step_to_stretch(1.0 + strain, dt_over_tau * kTau);
      ASSERT_TRUE(std::isfinite(stress));
      EXPECT_LE(stress, instantaneous_pa);
      const double expected = (g0 + g1 * std::exp(-k * dt_over_tau)) * instantaneous_pa;
      worst_relaxed = std::max(worst_relaxed, std::abs(stress / expected - 1.0));
      EXPECT_NEAR(stress / expected, 1.0, 1e-12) << "Δt = " << dt_over_tau << "τ";
    }
    // A ramp done in one long step relaxes as it goes: between relaxed and instantaneous.
    UniaxialDriver ramp(viscoelastic_tissue());
    const double ramped = ramp.step_to_stretch(1.0 + strain, dt_over_tau * kTau);
    EXPECT_GE(ramped, g0 * instantaneous_pa * (1.0 - 1e-12));
    EXPECT_LE(ramped, (g0 + g1 * kTau / (dt_over_tau * kTau)) * instantaneous_pa);

    // Creep above yield: the plastic part is exact for any Δt. The viscoelastic part reaches its
    // relaxed strain σ/E2 geometrically: at a held stress its error contracts by
    // g1·h/(g0 + g1·h) per step (h = τ/Δt when Δt ≫ τ: 0.12 at 10τ), from 57 % at the jump to
    // 1.3e-5 after five steps. Then Eq. 4 holds within the geometric O(ε·σ/(σ − σs)).
    const double stress_pa = 0.175, yield_pa = 0.075, n = 0.5, dt_s = dt_over_tau * kTau;
    const double eta2 = (stress_pa - yield_pa) * std::pow(5.0 * dt_s, n) / 1e-4;
    UniaxialDriver creep(viscoplastic_tissue(yield_pa, eta2, n));
    creep.step_to_nominal_stress(stress_pa, 0.0);
    for (int k = 1; k <= 5; ++k) {
      const double strain_now = creep.step_to_nominal_stress(stress_pa, dt_s) - 1.0;
      ASSERT_TRUE(std::isfinite(strain_now));
      const double plastic = (stress_pa - yield_pa) * std::pow(k * dt_s, n) / eta2;
      worst_plastic =
          std::max(worst_plastic, std::abs(creep.state().equivalent_plastic_strain / plastic - 1));
      EXPECT_NEAR(creep.state().equivalent_plastic_strain / plastic, 1.0, 1e-3);
      if (k == 5) {
        const double eq4 = sls_creep_strain(stress_pa, k * dt_s) + plastic;
        worst_eq4 = std::max(worst_eq4, std::abs(strain_now / eq4 - 1.0));
        EXPECT_NEAR(strain_now / eq4, 1.0, 1e-3);
      }
    }
  }
  RecordProperty("relaxation_vs_exact_decay", scientific(worst_relaxed));
  RecordProperty("plastic_vs_eq4", scientific(worst_plastic));
  RecordProperty("strain_vs_eq4_after_5_steps", scientific(worst_eq4));
}

TEST(ViscousTissue, ClosedFormFlowStopsAtTheYieldLimit) {
  // A long step at a strain far above yield: Δ(tⁿ) → ∞ and Δε → (σ_trial − σs)/(3G), the
  // rate-independent return to the yield surface; it never overshoots below the yield limit
  // (up to the geometric O(ε) of the linearised return).
  const double yield_pa = 0.05;
  const auto tissue = viscoplastic_tissue(yield_pa, 0.1, 0.5);
  for (double dt_s : {10.0 * kTau, 1e4 * kTau}) {
    const ViscousTissueStep step(tissue, dt_s);
    ViscousTissueState state, trial;
    const Eigen::Matrix3d F = Eigen::Vector3d(1.0 + 1e-4, 1.0 - 0.5e-4, 1.0 - 0.5e-4).asDiagonal();
    const Eigen::Matrix3d P = viscous_tissue_stress(F, step, state, trial);
    const Eigen::Matrix3d tau = P * F.transpose();
    const Eigen::Matrix3d deviator = tau - tau.trace() / 3.0 * Eigen::Matrix3d::Identity();
    const double equivalent = std::sqrt(1.5 * deviator.squaredNorm());
    ASSERT_GT(trial.equivalent_plastic_strain, 0.0);
    RecordProperty("dt_" + std::to_string(std::lround(dt_s)) + "_s_equivalent_over_yield_minus_1",
                   scientific(equivalent / yield_pa - 1.0));
    EXPECT_NEAR(equivalent / yield_pa, 1.0, 1e-3) << "Δt = " << dt_s << " s";
  }
}

// ---------------------------------------------------------------- invariance and robustness

TEST(ViscousTissue, ZeroStressAtRest) {
  const auto tissue = viscoplastic_tissue(0.0, 1.0, 0.5);  // yields under any stress
  for (double dt_s : {0.0, kTau, 1e4 * kTau}) {
    ViscousTissueState state;
    const Eigen::Matrix3d P =
        viscous_tissue_update(Eigen::Matrix3d::Identity(), ViscousTissueStep(tissue, dt_s), state);
    EXPECT_EQ(P.norm(), 0.0);  // P(I) = μI + U'(1)·I with U'(1) = −μ exactly
    EXPECT_EQ(state.equivalent_plastic_strain, 0.0);
  }
}

// A mesh's history in blocks: every element starts at rest, and what is stored for one element
// comes back from it alone, whichever block it is in (130 elements: two full blocks and a part).
TEST(ViscousHistory, StoresEachElementApartAtRestFirst) {
  ViscousHistory history(130);
  ASSERT_EQ(history.size(), 130u);
  const ViscousTissueState rest;
  for (std::size_t e = 0; e < history.size(); ++e) {
    const ViscousTissueState loaded = history.load(e);
    EXPECT_EQ(loaded.maxwell_stress_pa, rest.maxwell_stress_pa);
    EXPECT_EQ(loaded.elastic_stress_pa, rest.elastic_stress_pa);
    EXPECT_EQ(loaded.inverse_plastic_deformation, rest.inverse_plastic_deformation);
    EXPECT_EQ(loaded.equivalent_plastic_strain, 0.0);
    EXPECT_EQ(loaded.yield_clock_s, 0.0);
  }
  auto distinct = [](std::size_t e) {  // every field of every element a different value
    ViscousTissueState s;
    for (int k = 0; k < 6; ++k) {
      s.maxwell_stress_pa[k] = 1000.0 * e + k;
      s.elastic_stress_pa[k] = 1000.0 * e + 6 + k;
    }
    for (int k = 0; k < 9; ++k) s.inverse_plastic_deformation.data()[k] = 1000.0 * e + 12 + k;
    s.equivalent_plastic_strain = 1000.0 * e + 21;
    s.yield_clock_s = 1000.0 * e + 22;
    s.flow_stiffening = 1000.0 * e + 23;
    return s;
  };
  for (std::size_t e = 0; e < history.size(); ++e) history.store(e, distinct(e));
  for (std::size_t e = 0; e < history.size(); ++e) {
    const ViscousTissueState expected = distinct(e), loaded = history.load(e);
    EXPECT_EQ(loaded.maxwell_stress_pa, expected.maxwell_stress_pa);
    EXPECT_EQ(loaded.elastic_stress_pa, expected.elastic_stress_pa);
    EXPECT_EQ(loaded.inverse_plastic_deformation, expected.inverse_plastic_deformation);
    EXPECT_EQ(loaded.yield_clock_s, expected.yield_clock_s);
    EXPECT_EQ(loaded.flow_stiffening, expected.flow_stiffening);
    EXPECT_EQ(history.equivalent_plastic_strain(e), expected.equivalent_plastic_strain);
    EXPECT_EQ(history.inverse_plastic_deformation(e), expected.inverse_plastic_deformation);
    EXPECT_EQ(history.maxwell_stress_pa(e), expected.maxwell_stress_pa);
    // Components in ViscousTissueState's order, the layout the element loops read.
    for (int k = 0; k < ViscousHistory::kComponents; ++k)
      EXPECT_EQ(history.value(k, e), 1000.0 * e + k);
  }
}

TEST(ViscousTissue, TrialEvaluationLeavesTheCommittedStateAlone) {
  const auto tissue = viscoplastic_tissue(10.0, 50.0, 0.5);
  const ViscousTissueStep step(tissue, 0.01);
  Eigen::Matrix3d F;
  F << 1.1, 0.05, 0.0, -0.02, 0.95, 0.03, 0.01, 0.0, 0.97;
  ViscousTissueState committed, trial, updated;
  viscous_tissue_update(F, step, committed);
  const ViscousTissueState before = committed;
  const Eigen::Matrix3d trial_p = viscous_tissue_stress(1.02 * F, step, committed, trial);
  viscous_tissue_stress(0.9 * F, step, committed, trial);  // a second stage from the same state
  EXPECT_EQ(committed.maxwell_stress_pa, before.maxwell_stress_pa);
  EXPECT_EQ(committed.elastic_stress_pa, before.elastic_stress_pa);
  EXPECT_EQ(committed.inverse_plastic_deformation, before.inverse_plastic_deformation);
  EXPECT_EQ(committed.yield_clock_s, before.yield_clock_s);
  updated = committed;
  EXPECT_EQ(viscous_tissue_update(1.02 * F, step, updated), trial_p);
  EXPECT_GT(updated.equivalent_plastic_strain, before.equivalent_plastic_strain);
  // Stage 1 of the next Runge–Kutta step (Δt = 0 from the new state) sees the committed stress:
  // g = h = 1 and S_e unchanged leave H as it is, and Δ(tⁿ) = 0 stops the flow. Round-off only.
  ViscousTissueState scratch;
  const Eigen::Matrix3d stage_one =
      viscous_tissue_stress(1.02 * F, ViscousTissueStep(tissue, 0.0), updated, scratch);
  EXPECT_LE((stage_one - trial_p).norm(), 1e-13 * trial_p.norm());
}

TEST(ViscousTissue, ObjectiveUnderRotationsAlongTheHistory) {
  // Two histories, F_k and R_k·F_k with a different rigid rotation at every step: the state lives
  // in the intermediate configuration, so both must carry identical states and identical
  // S = F⁻¹P, while P rotates: P(R·F) = R·P(F). Only round-off separates them; 1e-11 relative
  // leaves room for a few hundred operations on numbers of order one per step.
  const auto tissue = viscoplastic_tissue(50.0, 100.0, 0.5);  // yields along this history
  const ViscousTissueStep step(tissue, 0.05);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  ViscousTissueState plain, rotated;
  double worst = 0.0;
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  for (int k = 0; k < 30; ++k) {
    for (int i = 0; i < 9; ++i) F(i / 3, i % 3) += 0.03 * u(random);
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(3.0 * u(random),
                          Eigen::Vector3d(u(random), u(random), u(random)).normalized())
            .toRotationMatrix();
    const Eigen::Matrix3d P = viscous_tissue_update(F, step, plain);
    const Eigen::Matrix3d P_rotated = viscous_tissue_update(R * F, step, rotated);
    const double scale = P.norm();
    EXPECT_LE((P_rotated - R * P).norm(), 1e-11 * scale) << "step " << k;
    const Eigen::Matrix3d S = F.inverse() * P, S_rotated = (R * F).inverse() * P_rotated;
    worst =
        std::max({worst, (P_rotated - R * P).norm() / scale, (S_rotated - S).norm() / S.norm()});
    EXPECT_LE((S_rotated - S).norm(), 1e-11 * S.norm()) << "step " << k;
    EXPECT_LE((rotated.inverse_plastic_deformation - plain.inverse_plastic_deformation).norm(),
              1e-11);
  }
  RecordProperty("worst_relative_difference", scientific(worst));
  EXPECT_GT(plain.equivalent_plastic_strain, 1e-3);  // the history did flow plastically
}

TEST(ViscousTissue, FiniteAtZeroAndNegativeVolume) {
  const auto tissue = viscoplastic_tissue(20.0, 50.0, 0.5);
  const ViscousTissueStep step(tissue, 0.01);
  ViscousTissueState state;
  Eigen::Matrix3d stretched;
  stretched << 1.3, 0.1, 0.0, 0.0, 0.8, 0.05, 0.02, 0.0, 0.9;
  for (int k = 0; k < 20; ++k) viscous_tissue_update(stretched, step, state);
  ASSERT_GT(state.equivalent_plastic_strain, 0.0);

  Eigen::Matrix3d flat = stretched, inverted = stretched;
  flat.col(2).setZero();    // J = 0
  inverted.col(2) *= -1.0;  // J < 0
  for (const Eigen::Matrix3d& F : {flat, inverted, Eigen::Matrix3d::Zero().eval(), stretched}) {
    const Eigen::Matrix3d P = viscous_tissue_update(F, step, state);
    EXPECT_TRUE(P.allFinite()) << "J = " << F.determinant();
    EXPECT_TRUE(state.inverse_plastic_deformation.allFinite());
    for (double v : state.maxwell_stress_pa) EXPECT_TRUE(std::isfinite(v));
  }
}

TEST(ViscousTissue, BadParametersAreNamed) {
  struct Case {
    ViscousTissueParameters parameters;
    const char* name;
  };
  const double nan = std::nan("");
  const ViscoplasticParameters vp{1.0, 10.0, 0.5};
  const Case cases[] = {
      {{{0.0, kE2, kEta1}, kNu, std::nullopt}, "E1"},
      {{{kE1, nan, kEta1}, kNu, std::nullopt}, "E2"},
      {{{kE1, kE2, -1.0}, kNu, std::nullopt}, "η1"},
      {{{kE1, kE2, kEta1}, 0.5, std::nullopt}, "Poisson"},
      {{{kE1, kE2, kEta1}, kNu, ViscoplasticParameters{-1.0, 10.0, 0.5}}, "yield limit"},
      {{{kE1, kE2, kEta1}, kNu, ViscoplasticParameters{1.0, 0.0, 0.5}}, "η2"},
      {{{kE1, kE2, kEta1}, kNu, ViscoplasticParameters{1.0, 10.0, 0.0}}, "creep index"},
      {{{kE1, kE2, kEta1}, kNu, ViscoplasticParameters{1.0, 10.0, 1.5}}, "creep index"},
      {{{kE1, kE2, kEta1}, kNu, ViscoplasticParameters{1.0, 10.0, nan}}, "creep index"},
  };
  for (const Case& c : cases) {
    const auto message = validate(c.parameters);
    ASSERT_TRUE(message.has_value()) << c.name;
    EXPECT_NE(message->find(c.name), std::string::npos) << *message;
  }
  EXPECT_FALSE(validate(viscoplastic_tissue(0.0, 10.0, 1.0)).has_value());
  EXPECT_FALSE(validate(vp).has_value());
  EXPECT_THROW(ViscousTissueStep(viscoelastic_tissue(), -1e-3), std::invalid_argument);
  EXPECT_THROW(UniaxialDriver(cases[0].parameters), std::invalid_argument);
}

}  // namespace
}  // namespace liversim
