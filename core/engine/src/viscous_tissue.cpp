#include "liversim/engine/viscous_tissue.h"
#include "liversim/engine/validation_message.h"

#include "liversim/engine/material.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace liversim {
namespace {

const auto& out_of_range = out_of_range_message;

bool positive(double value) {
  return std::isfinite(value) && value > 0.0;
}

Eigen::Matrix3d from_voigt(const std::array<double, 6>& v) {
  Eigen::Matrix3d m;
  m << v[0], v[5], v[4], v[5], v[1], v[3], v[4], v[3], v[2];
  return m;
}

std::array<double, 6> to_voigt(const Eigen::Matrix3d& m) {
  return {m(0, 0), m(1, 1), m(2, 2), m(1, 2), m(0, 2), m(0, 1)};
}

Eigen::Matrix3d symmetric_part(const Eigen::Matrix3d& m) {
  return 0.5 * (m + m.transpose());
}

// (t + Δt)ⁿ − tⁿ without the cancellation of the plain difference when Δt ≪ t.
double clock_power_increment(double clock_s, double dt_s, double n) {
  if (clock_s <= 0.0) return std::pow(dt_s, n);
  return std::pow(clock_s, n) * std::expm1(n * std::log1p(dt_s / clock_s));
}

// exp(A) by scaling and squaring of its Taylor series, summed until a term is below 1e-17 of
// the identity (‖A/2ˢ‖ ≤ 1/8, so a few terms for the small increments of a real-time step).
// A rotation of A rotates every term, so the result is objective to round-off, which an
// eigen-decomposition in closed form is not.
Eigen::Matrix3d matrix_exponential(const Eigen::Matrix3d& a) {
  const int squarings = std::max(0, static_cast<int>(std::ceil(std::log2(8.0 * a.norm()))));
  const Eigen::Matrix3d scaled = std::ldexp(1.0, -squarings) * a;
  Eigen::Matrix3d term = Eigen::Matrix3d::Identity(), result = term;
  for (int k = 1; k <= 20 && term.squaredNorm() > 1e-34; ++k) {
    term = (1.0 / k) * (term * scaled);
    result += term;
  }
  for (int i = 0; i < squarings; ++i) result = result * result;
  return result;
}

// Neo-Hookean 2nd Piola–Kirchhoff stress Fe⁻¹·P(Fe) of the instantaneous base in the
// intermediate configuration (symmetric up to round-off).
Eigen::Matrix3d elastic_pk2(const Eigen::Matrix3d& fe, const Eigen::Matrix3d& fe_inverse,
                            const ViscousTissueStep& step) {
  return symmetric_part(
      fe_inverse * neo_hookean::first_piola_stress(fe, step.mu_instant_pa, step.lambda_instant_pa));
}

}  // namespace

double maxwell_arm_energy_density(const std::array<double, 6>& h, double arm_fraction, double mu,
                                  double lambda) {
  // C⁻¹ = (I − λ/(2μ + 3λ)·1⊗1)/(2μ); H in Voigt order (xx, yy, zz, yz, xz, xy).
  const double trace = h[0] + h[1] + h[2];
  const double contraction =
      h[0] * h[0] + h[1] * h[1] + h[2] * h[2] + 2.0 * (h[3] * h[3] + h[4] * h[4] + h[5] * h[5]);
  return arm_fraction / (4.0 * mu) *
         (contraction - lambda / (2.0 * mu + 3.0 * lambda) * trace * trace);
}

std::optional<std::string> validate(const ViscoelasticParameters& p) {
  if (!positive(p.e1_pa)) return out_of_range("E1 (Pa)", p.e1_pa, "a finite value > 0");
  if (!positive(p.e2_pa)) return out_of_range("E2 (Pa)", p.e2_pa, "a finite value > 0");
  if (!positive(p.eta1_pa_s)) return out_of_range("η1 (Pa·s)", p.eta1_pa_s, "a finite value > 0");
  return std::nullopt;
}

std::optional<std::string> validate(const ViscoplasticParameters& p) {
  if (!std::isfinite(p.yield_limit_pa) || p.yield_limit_pa < 0.0)
    return out_of_range("yield limit σs (Pa)", p.yield_limit_pa, "a finite value ≥ 0");
  if (!positive(p.eta2_pa_s_pow_n))
    return out_of_range("η2 (Pa·sⁿ)", p.eta2_pa_s_pow_n, "a finite value > 0");
  // n > 1 would make the creep rate under a held load grow without bound (tertiary creep, i.e.
  // rupture), which belongs to the cutting model, not to this law.
  if (!std::isfinite(p.creep_index_n) || p.creep_index_n <= 0.0 || p.creep_index_n > 1.0)
    return out_of_range("creep index n", p.creep_index_n, "a value in (0, 1]");
  return std::nullopt;
}

std::optional<std::string> validate(const ViscousTissueParameters& p) {
  if (auto message = validate(p.viscoelastic)) return message;
  if (!std::isfinite(p.poisson_ratio) || p.poisson_ratio <= -1.0 || p.poisson_ratio >= 0.5)
    return out_of_range("Poisson's ratio", p.poisson_ratio, "a value in (-1, 0.5)");
  if (p.viscoplastic) return validate(*p.viscoplastic);
  return std::nullopt;
}

ViscousTissueStep::ViscousTissueStep(const ViscousTissueParameters& parameters, double dt)
    : dt_s(dt), viscoplastic(parameters.viscoplastic), flow_dt_s(dt) {
  if (!(dt >= 0.0) || !std::isfinite(dt))
    throw std::invalid_argument("time step " + std::to_string(dt) + " s is not a finite value ≥ 0");
  const ViscoelasticParameters& ve = parameters.viscoelastic;
  const TissueMaterial instant{ve.instantaneous_modulus_pa(), parameters.poisson_ratio, 1.0};
  mu_instant_pa = instant.shear_modulus_pa();
  lambda_instant_pa = instant.lame_lambda_pa();
  relaxed_fraction = ve.e2_pa / ve.instantaneous_modulus_pa();
  arm_fraction = ve.e1_pa / ve.instantaneous_modulus_pa();
  // Exact for an elastic stress linear in time over the step; g, h ∈ (0, 1] for every Δt, so
  // the update cannot amplify the arm's stress however long the step.
  relaxation_time_s = ve.relaxation_time_s();
  const double x = dt / relaxation_time_s;
  arm_decay = std::exp(-x);
  arm_loading = x > 0.0 ? -std::expm1(-x) / x : 1.0;
  step_shear_modulus_pa = (relaxed_fraction + arm_fraction * arm_loading) * mu_instant_pa;
}

ViscousTissueStep ViscousTissueStep::plastic_flow_only(const ViscousTissueParameters& parameters,
                                                       double dt_s) {
  ViscousTissueStep step(parameters, dt_s);
  step.arm_decay = 1.0;
  step.arm_loading = 1.0;
  step.step_shear_modulus_pa = step.mu_instant_pa;  // both springs carry the flow's unloading
  return step;
}

Eigen::Matrix3d viscoelastic_stress_rate_form(const Eigen::Matrix3d& F,
                                              const ViscousTissueStep& step,
                                              const Eigen::Matrix3d& fp_inverse,
                                              const Voigt6& q_known, double keep,
                                              double elastic_weight, Voigt6& elastic_stress) {
  const Eigen::Matrix3d fe = F * fp_inverse;
  const Eigen::Matrix3d cof = cofactor(fe);
  const double J = fe.col(0).dot(cof.col(0));
  const Eigen::Matrix3d q = from_voigt(q_known);
  const Eigen::Matrix3d p_elastic =
      neo_hookean::first_piola_stress(fe, step.mu_instant_pa, step.lambda_instant_pa);
  if (!(J >= neo_hookean::kMinVolumeRatio)) {
    // S_e is unbounded as J → 0: freeze the arm, keep P finite through the continuation.
    elastic_stress = q_known;
    return (p_elastic - step.arm_fraction * fe * q) * fp_inverse.transpose();
  }
  const Eigen::Matrix3d elastic = symmetric_part((cof.transpose() / J) * p_elastic);
  elastic_stress = to_voigt(elastic);
  // S̄ = S_e − g1·(keep·Q + w·S_e), P = Fe·S̄·Fp⁻ᵀ.
  const double g1 = step.arm_fraction;
  return ((1.0 - g1 * elastic_weight) * p_elastic - g1 * keep * fe * q) * fp_inverse.transpose();
}

Eigen::Matrix<double, 9, 9> viscoelastic_stress_tangent_rate_form(
    const Eigen::Matrix3d& F, const ViscousTissueStep& step, const Eigen::Matrix3d& fp_inverse,
    const Voigt6& q_known, double keep, double elastic_weight) {
  const Eigen::Matrix3d fe = F * fp_inverse;
  const bool collapsed = !(fe.determinant() >= neo_hookean::kMinVolumeRatio);
  const double elastic_scale = collapsed ? 1.0 : 1.0 - step.arm_fraction * elastic_weight;
  if (collapsed) keep = 1.0;  // the frozen arm, as in the stress
  // Row-major flattening: vec(A·B) = (I ⊗ Bᵀ)·vec(A) and vec(A·B) = (A ⊗ I)·vec(B).
  auto right_factor = [](const Eigen::Matrix3d& b) {
    Eigen::Matrix<double, 9, 9> m = Eigen::Matrix<double, 9, 9>::Zero();
    for (int i = 0; i < 3; ++i) m.block<3, 3>(3 * i, 3 * i) = b.transpose();
    return m;
  };
  // P = c·P_e(F·Fp⁻¹)·Fp⁻ᵀ − g1·keep·F·(Fp⁻¹·Q·Fp⁻ᵀ).
  const Eigen::Matrix<double, 9, 9> elastic =
      neo_hookean::stress_tangent(fe, step.mu_instant_pa, step.lambda_instant_pa);
  const Eigen::Matrix3d w = fp_inverse * from_voigt(q_known) * fp_inverse.transpose();
  return elastic_scale * right_factor(fp_inverse.transpose()) * elastic * right_factor(fp_inverse) -
         step.arm_fraction * keep * right_factor(w);
}

namespace {

// Equivalent (von Mises) deviatoric Hencky strain of Fe: √(2/3)·|dev ln V|, V² = Fe·Feᵀ.
double elastic_equivalent_strain(const Eigen::Matrix3d& fe) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> stretch_squared;
  stretch_squared.computeDirect(fe * fe.transpose(), Eigen::EigenvaluesOnly);
  const Eigen::Array3d log_stretch =
      0.5 * stretch_squared.eigenvalues().array().max(std::numeric_limits<double>::min()).log();
  return std::sqrt(2.0 / 3.0 * (log_stretch - log_stretch.mean()).matrix().squaredNorm());
}

// σ_max(Fp⁻¹)² (ViscousTissueState::flow_stiffening); at least 1, as det Fp⁻¹ = 1.
double flow_stiffening(const Eigen::Matrix3d& fp_inverse) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> squared;
  squared.computeDirect(fp_inverse * fp_inverse.transpose(), Eigen::EigenvaluesOnly);
  return std::max(1.0, squared.eigenvalues()(2));
}

}  // namespace

Eigen::Matrix3d viscous_tissue_stress(const Eigen::Matrix3d& F, const ViscousTissueStep& step,
                                      const ViscousTissueState& committed,
                                      ViscousTissueState& trial, double yield_raise_pa) {
  const Eigen::Matrix3d arm_before = from_voigt(committed.maxwell_stress_pa);
  const Eigen::Matrix3d elastic_before = from_voigt(committed.elastic_stress_pa);
  Eigen::Matrix3d fp_inverse = committed.inverse_plastic_deformation;
  Eigen::Matrix3d fe = F * fp_inverse;
  Eigen::Matrix3d cof = cofactor(fe);
  const double J = fe.col(0).dot(cof.col(0));  // det Fe = det F: Fp is isochoric

  if (!(J >= neo_hookean::kMinVolumeRatio)) {
    // Collapsed or inverted: P stays finite through the Neo-Hookean continuation and Fe·H.
    const Eigen::Matrix3d arm = step.arm_decay * arm_before;
    trial = committed;
    trial.maxwell_stress_pa = to_voigt(arm);
    return (step.relaxed_fraction *
                neo_hookean::first_piola_stress(fe, step.mu_instant_pa, step.lambda_instant_pa) +
            step.arm_fraction * fe * arm) *
           fp_inverse.transpose();
  }

  auto arm_after = [&](const Eigen::Matrix3d& elastic) {
    return step.arm_decay * arm_before + step.arm_loading * (elastic - elastic_before);
  };
  Eigen::Matrix3d elastic = elastic_pk2(fe, cof.transpose() / J, step);
  Eigen::Matrix3d arm = arm_after(elastic);
  Eigen::Matrix3d pk2 = step.relaxed_fraction * elastic + step.arm_fraction * arm;
  double plastic_strain = committed.equivalent_plastic_strain;
  double clock_s = committed.yield_clock_s;
  double stiffening = committed.flow_stiffening;

  if (step.viscoplastic && step.flow_dt_s > 0.0) {
    const ViscoplasticParameters& vp = *step.viscoplastic;
    const Eigen::Matrix3d kirchhoff = symmetric_part(fe * pk2 * fe.transpose());
    const Eigen::Matrix3d deviator =
        kirchhoff - kirchhoff.trace() / 3.0 * Eigen::Matrix3d::Identity();
    const double equivalent_pa = std::sqrt(1.5 * deviator.squaredNorm());
    const double yield_limit_pa = vp.yield_limit_pa + yield_raise_pa;
    if (equivalent_pa > yield_limit_pa && committed.flow_stiffening < kMaxFlowStiffening) {
      // Time hardening with increments of tⁿ (exact under a held stress, never the singular
      // rate n·tⁿ⁻¹), solved implicitly in closed form: the end-of-step equivalent stress is
      // σ_trial − 3·G·Δε, so Δε·η2 = (σ_end − σs)·Δ(tⁿ) gives the expression below. However
      // long the step, the stress stops at the yield limit, not below it (to first order in the
      // strain).
      const double clock_increment =
          clock_power_increment(clock_s, step.flow_dt_s, vp.creep_index_n);
      clock_s += step.flow_dt_s;
      double increment = (equivalent_pa - yield_limit_pa) * clock_increment /
                         (vp.eta2_pa_s_pow_n + 3.0 * step.step_shear_modulus_pa * clock_increment);
      // No more than the share above yield of the elastic strain there is to flow out (its
      // equivalent Hencky strain): a radial return, exact for a Hencky law. The increment above
      // takes the step's modulus; the Neo-Hookean stress outgrows 3·G·ε at large stretch, and a
      // flow by that stress overshot the elastic strain, reversed it the next step, and ran away
      // (a lifted specimen's neck reached a plastic strain of 28, Fp⁻¹ ~ 10⁶, then NaN).
      increment = std::min(increment,
                           elastic_equivalent_strain(fe) * (1.0 - yield_limit_pa / equivalent_pa));
      if (increment > 0.0) {
        // Fe ← exp(−Δε·N)·Fe with N = (3/2)·dev τ/σ_eq: flow along the Kirchhoff deviator,
        // exactly isochoric (tr N = 0).
        const Eigen::Matrix3d to_intermediate = fp_inverse * (cof.transpose() / J);
        auto flowed = [&](double by) {
          Eigen::Matrix3d m =
              to_intermediate * matrix_exponential(-by * 1.5 / equivalent_pa * deviator) * fe;
          return Eigen::Matrix3d(m / std::cbrt(m.determinant()));  // det Fp = 1 against round-off
        };
        Eigen::Matrix3d flowed_inverse = flowed(increment);
        double flowed_stiffening = flow_stiffening(flowed_inverse);
        if (flowed_stiffening > kMaxFlowStiffening && flowed_stiffening > stiffening) {
          // Stop at the limit: ln σ_max² grows about linearly along the flow (exactly on a
          // proportional path), so one rescaled increment lands on it.
          increment *=
              std::log(kMaxFlowStiffening / stiffening) / std::log(flowed_stiffening / stiffening);
          flowed_inverse = flowed(increment);
          flowed_stiffening = flow_stiffening(flowed_inverse);
        }
        fp_inverse = flowed_inverse;
        plastic_strain += increment;
        stiffening = flowed_stiffening;

        fe = F * fp_inverse;
        cof = cofactor(fe);
        elastic = elastic_pk2(fe, cof.transpose() / fe.col(0).dot(cof.col(0)), step);
        arm = arm_after(elastic);
        pk2 = step.relaxed_fraction * elastic + step.arm_fraction * arm;
      }
    }
  }

  trial.maxwell_stress_pa = to_voigt(arm);
  trial.elastic_stress_pa = to_voigt(elastic);
  trial.inverse_plastic_deformation = fp_inverse;
  trial.equivalent_plastic_strain = plastic_strain;
  trial.yield_clock_s = clock_s;
  trial.flow_stiffening = stiffening;
  return fe * pk2 * fp_inverse.transpose();  // P = F·S with S = Fp⁻¹·S̄·Fp⁻ᵀ
}

Eigen::Matrix3d viscous_tissue_update(const Eigen::Matrix3d& F, const ViscousTissueStep& step,
                                      ViscousTissueState& state, double yield_raise_pa) {
  return viscous_tissue_stress(F, step, state, state, yield_raise_pa);
}

// ---------------------------------------------------------------- history of a mesh

ViscousHistory::ViscousHistory(std::size_t elements)
    : elements_(elements),
      values_((elements + kBlock - 1) / kBlock * kBlock * kComponents, 0.0),
      plastic_blocks_((elements + kBlock - 1) / kBlock, 0) {
  for (std::size_t e = 0; e < elements; ++e) {
    for (int k : {0, 4, 8})  // the diagonal of Fp⁻¹, column-major
      slot(kInversePlasticDeformation + k, e) = 1.0;
    slot(kFlowStiffening, e) = 1.0;
  }
}

ViscousTissueState ViscousHistory::load(std::size_t e) const {
  ViscousTissueState history;
  for (int k = 0; k < 6; ++k) {
    history.maxwell_stress_pa[k] = value(kMaxwellStress + k, e);
    history.elastic_stress_pa[k] = value(kElasticStress + k, e);
  }
  history.inverse_plastic_deformation = inverse_plastic_deformation(e);
  history.equivalent_plastic_strain = value(kEquivalentPlasticStrain, e);
  history.yield_clock_s = value(kYieldClock, e);
  history.flow_stiffening = value(kFlowStiffening, e);
  return history;
}

void ViscousHistory::store(std::size_t e, const ViscousTissueState& history) {
  for (int k = 0; k < 6; ++k) {
    slot(kMaxwellStress + k, e) = history.maxwell_stress_pa[k];
    slot(kElasticStress + k, e) = history.elastic_stress_pa[k];
  }
  for (int k = 0; k < 9; ++k)
    slot(kInversePlasticDeformation + k, e) = history.inverse_plastic_deformation.data()[k];
  slot(kEquivalentPlasticStrain, e) = history.equivalent_plastic_strain;
  slot(kYieldClock, e) = history.yield_clock_s;
  slot(kFlowStiffening, e) = history.flow_stiffening;
  note_flow(e);
}

double ViscousHistory::largest_flow_stiffening() const {
  double largest = 1.0;
  for (std::size_t b = 0; b < plastic_blocks_.size(); ++b) {
    if (plastic_blocks_[b] == 0) continue;
    const double* stiffening = values_.data() + (b * kComponents + kFlowStiffening) * kBlock;
    const std::size_t count = std::min(kBlock, elements_ - b * kBlock);
    for (std::size_t i = 0; i < count; ++i) largest = std::max(largest, stiffening[i]);
  }
  return largest;
}

void ViscousHistory::copy_element(const ViscousHistory& from, std::size_t from_e,
                                  std::size_t to_e) {
  for (int k = 0; k < kComponents; ++k) slot(k, to_e) = from.value(k, from_e);
  note_flow(to_e);
}

void ViscousHistory::note_flow(std::size_t e) {
  if (inverse_plastic_deformation(e) != Eigen::Matrix3d::Identity())
    plastic_blocks_[e / kBlock] = 1;
}

Eigen::Matrix3d ViscousHistory::inverse_plastic_deformation(std::size_t e) const {
  Eigen::Matrix3d fp_inverse;  // Eigen's default storage is column-major, as the components
  for (int k = 0; k < 9; ++k) fp_inverse.data()[k] = value(kInversePlasticDeformation + k, e);
  return fp_inverse;
}

Voigt6 ViscousHistory::maxwell_stress_pa(std::size_t e) const {
  Voigt6 h;
  for (int k = 0; k < 6; ++k) h[k] = value(kMaxwellStress + k, e);
  return h;
}

// ---------------------------------------------------------------- uniaxial driver

UniaxialDriver::UniaxialDriver(const ViscousTissueParameters& parameters)
    : parameters_(parameters) {
  if (auto message = validate(parameters)) throw std::invalid_argument(*message);
}

namespace {

// Newton's method on the stretches (λ_axial, λ_lateral) with a central-difference Jacobian,
// evaluating trial stresses from the committed state. `residual` maps the trial P to the
// residuals; `free_axial` says whether the axial stretch is an unknown.
template <typename Residual>
Eigen::Matrix3d solve_uniaxial(const ViscousTissueStep& step, const ViscousTissueState& committed,
                               bool free_axial, Residual residual, double& axial, double& lateral,
                               ViscousTissueState& trial) {
  auto evaluate = [&](double a, double l, ViscousTissueState& out) {
    return viscous_tissue_stress(Eigen::Vector3d(a, l, l).asDiagonal(), step, committed, out);
  };
  // The stress is smooth in the stretches away from the yield kink; 1e-6 balances the O(δ²)
  // truncation against round-off of stresses of order λ·δ.
  constexpr double kDelta = 1e-6, kTolerance = 1e-14;
  ViscousTissueState scratch;
  double previous_size = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < 50; ++iteration) {
    const Eigen::Vector2d r = residual(evaluate(axial, lateral, trial));
    Eigen::Matrix2d jacobian = Eigen::Matrix2d::Identity();
    for (int k = free_axial ? 0 : 1; k < 2; ++k) {
      const double da = k == 0 ? kDelta : 0.0, dl = k == 1 ? kDelta : 0.0;
      jacobian.col(k) = (residual(evaluate(axial + da, lateral + dl, scratch)) -
                         residual(evaluate(axial - da, lateral - dl, scratch))) /
                        (2.0 * kDelta);
    }
    Eigen::Vector2d correction = -jacobian.partialPivLu().solve(r);
    if (!free_axial) correction(0) = 0.0;
    axial += correction(0);
    lateral += correction(1);
    // Converged, or stalled at the round-off floor of the residual (large, soft plastic states):
    // near the solution Newton would otherwise at least halve the correction.
    const double size = correction.cwiseAbs().maxCoeff();
    if (size <= kTolerance || (size <= 1e-9 && size >= 0.5 * previous_size))
      return evaluate(axial, lateral, trial);
    previous_size = size;
  }
  throw std::runtime_error("uniaxial driver: Newton's method did not converge");
}

}  // namespace

double UniaxialDriver::step_to_stretch(double axial_stretch, double dt_s) {
  const ViscousTissueStep step(parameters_, dt_s);
  ViscousTissueState trial;
  double lateral = lateral_stretch_;
  const Eigen::Matrix3d P = solve_uniaxial(
      step, state_, false, [](const Eigen::Matrix3d& p) { return Eigen::Vector2d(0.0, p(1, 1)); },
      axial_stretch, lateral, trial);
  state_ = trial;
  axial_stretch_ = axial_stretch;
  lateral_stretch_ = lateral;
  return P(0, 0);
}

double UniaxialDriver::step_to_nominal_stress(double nominal_stress_pa, double dt_s) {
  const ViscousTissueStep step(parameters_, dt_s);
  ViscousTissueState trial;
  double axial = axial_stretch_, lateral = lateral_stretch_;
  solve_uniaxial(
      step, state_, true,
      [nominal_stress_pa](const Eigen::Matrix3d& p) {
        return Eigen::Vector2d(p(0, 0) - nominal_stress_pa, p(1, 1));
      },
      axial, lateral, trial);
  state_ = trial;
  axial_stretch_ = axial;
  lateral_stretch_ = lateral;
  return axial_stretch_;
}

ViscoelasticParameters seed_viscoelastic_split(double youngs_modulus_pa) {
  const double seed_e_pa = kSeedViscoelastic.instantaneous_modulus_pa();
  return {youngs_modulus_pa * kSeedViscoelastic.e1_pa / seed_e_pa,
          youngs_modulus_pa * kSeedViscoelastic.e2_pa / seed_e_pa, kSeedViscoelastic.eta1_pa_s};
}

ViscoelasticParameters with_instantaneous_modulus(const ViscoelasticParameters& law,
                                                  double youngs_modulus_pa) {
  const double old_e_pa = law.instantaneous_modulus_pa();
  if (!(old_e_pa > 0.0)) return seed_viscoelastic_split(youngs_modulus_pa);
  const double scale = youngs_modulus_pa / old_e_pa;
  return {law.e1_pa * scale, law.e2_pa * scale, law.eta1_pa_s};
}

ViscoelasticParameters with_maxwell_arm(const ViscoelasticParameters& law, double e1_pa,
                                        double youngs_modulus_pa) {
  return {e1_pa, youngs_modulus_pa - e1_pa, law.eta1_pa_s};
}

}  // namespace liversim
