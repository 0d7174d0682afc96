#pragma once
// Finite-strain viscoelasticity and viscoplasticity at one material point: the seed's
// three-element model (standard linear solid, Eq. 1–3) with a nonlinear viscoplastic element in
// series above a yield limit (Eq. 4). See docs/viscous-tissue.md for the formulation and its
// verification.
//
// Moduli: the seed quotes a single E = 3500 Pa. We take it as the INSTANTANEOUS small-strain
// modulus E1 + E2 (before the dashpot moves both springs carry load): the instantaneous response
// is the stiffest, so it is the one the explicit stable step must be computed with. The relaxed
// (long-term) modulus is E2. Shear and bulk response relax by the same factor, so Poisson's ratio
// is the same at every instant and the 3-D uniaxial response is exactly the 1-D model.

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace liversim {

// Seed Eq. 1–3: spring E2 in parallel with a Maxwell arm (spring E1 in series with dashpot η1).
struct ViscoelasticParameters {
  double e1_pa;      // spring of the Maxwell arm
  double e2_pa;      // parallel spring: the relaxed modulus
  double eta1_pa_s;  // dashpot of the Maxwell arm

  double instantaneous_modulus_pa() const { return e1_pa + e2_pa; }
  // τ = η1/E1: the decay time of the stress at held strain (Eq. 2).
  double relaxation_time_s() const { return eta1_pa_s / e1_pa; }
  // τc = (E1 + E2)·τ/E2: the decay time of the strain at held stress (Eq. 3).
  double retardation_time_s() const {
    return instantaneous_modulus_pa() * relaxation_time_s() / e2_pa;
  }
};

// The seed's parenchyma split into its arms: E = E1 + E2 = 3500 Pa with E1 : E2 = 4 : 3, and
// η1 = 2000 Pa·s (τ = η1/E1 = 1 s). The seed gives E and the arms' roles, not this split; it is
// the split every study and default here assumes (docs/viscous-tissue.md).
inline constexpr ViscoelasticParameters kSeedViscoelastic{2000.0, 1500.0, 2000.0};

// The seed's split of another instantaneous modulus E: E1 = 4/7·E, E2 = 3/7·E, its η1.
ViscoelasticParameters seed_viscoelastic_split(double youngs_modulus_pa);
// E = E1 + E2 is the tissue's Young's modulus. A new E scales both arms by E_new/E_old, so the
// relaxation keeps its shape (τ changes with E1); without an old E (≤ 0) the seed's split is taken.
ViscoelasticParameters with_instantaneous_modulus(const ViscoelasticParameters& law,
                                                  double youngs_modulus_pa);
// A new Maxwell arm E1 with E held: E2 = E − E1 follows.
ViscoelasticParameters with_maxwell_arm(const ViscoelasticParameters& law, double e1_pa,
                                        double youngs_modulus_pa);

// Seed Eq. 4: above the yield limit σs a viscoplastic element in series creeps by
// (σ − σs)·tⁿ/η2, σ being the von Mises equivalent of the Kirchhoff stress in 3-D.
struct ViscoplasticParameters {
  double yield_limit_pa;   // σs (0: creep under any deviatoric stress)
  double eta2_pa_s_pow_n;  // η2 in Pa·sⁿ
  double creep_index_n;    // n in (0, 1]: primary (n < 1) or steady (n = 1) creep
};

struct ViscousTissueParameters {
  ViscoelasticParameters viscoelastic;
  double poisson_ratio;  // of the compressible Neo-Hookean base, at every instant
  std::optional<ViscoplasticParameters> viscoplastic;  // none: the viscoelastic model alone
};

// Each returns a message naming the first parameter that is outside its range (or not a number),
// or nothing when all are valid.
std::optional<std::string> validate(const ViscoelasticParameters& parameters);
std::optional<std::string> validate(const ViscoplasticParameters& parameters);
std::optional<std::string> validate(const ViscousTissueParameters& parameters);

// Constants of one step length, shared by every element of a material: build one per step length
// (per distinct stage length of a Runge–Kutta step), not one per element (it costs an exp).
struct ViscousTissueStep {
  // `parameters` must be valid (see validate). Throws std::invalid_argument unless dt_s ≥ 0
  // (dt_s = 0: an instantaneous, purely elastic change of deformation).
  ViscousTissueStep(const ViscousTissueParameters& parameters, double dt_s);

  double dt_s;
  double relaxation_time_s;  // τ = η1/E1
  double mu_instant_pa;      // Lamé parameters of the instantaneous modulus E1 + E2
  double lambda_instant_pa;
  double relaxed_fraction;       // g0 = E2/(E1 + E2)
  double arm_fraction;           // g1 = E1/(E1 + E2)
  double arm_decay;              // g = exp(−Δt/τ)
  double arm_loading;            // h = (1 − g)/(Δt/τ): weight of this step's elastic increment
  double step_shear_modulus_pa;  // (g0 + g1·h)·μ: shear stiffness of the response within the step
  std::optional<ViscoplasticParameters> viscoplastic;
  // The time the plastic flow of this step covers (dt_s unless set): the explicit scheme lets the
  // flow of several steps be taken at once (SimModel::plastic_flow_interval_s); 0: no flow.
  double flow_dt_s;

  // A step whose Maxwell arm follows the elastic stress without relaxing (g = h = 1): plastic
  // flow alone over dt_s, for integrators that advance the arm in their own state (see
  // viscoelastic_stress_rate_form) and apply the flow after each step.
  static ViscousTissueStep plastic_flow_only(const ViscousTissueParameters& parameters,
                                             double dt_s);
};

// Symmetric tensor in Voigt order (xx, yy, zz, yz, xz, xy).
using Voigt6 = std::array<double, 6>;

// Energy density (J/m³) held by the Maxwell arm's spring with arm variable H (its stress is
// g1·H): ½·g1·H : C⁻¹ : H, C the instantaneous isotropic stiffness (Lamé μ, λ). Exact at small
// strain, as the seed's 1-D model; the finite-strain arm has no closed-form potential. The
// dashpot dissipates 2/τ of it per second.
double maxwell_arm_energy_density(const std::array<double, 6>& h, double arm_fraction, double mu,
                                  double lambda);
// The same with a step's material constants.
inline double maxwell_arm_energy_density(const std::array<double, 6>& h,
                                         const ViscousTissueStep& step) {
  return maxwell_arm_energy_density(h, step.arm_fraction, step.mu_instant_pa,
                                    step.lambda_instant_pa);
}

// History of one element, committed once per step. Its tensors live in the intermediate
// configuration of F = Fe·Fp (unloaded, plastically deformed), so a rigid rotation of the
// current configuration leaves the state unchanged. 24 doubles.
struct ViscousTissueState {
  // Symmetric tensors in Voigt order (xx, yy, zz, yz, xz, xy), 2nd Piola–Kirchhoff-like, Pa.
  std::array<double, 6> maxwell_stress_pa{};  // H: the Maxwell arm carries g1·H
  std::array<double, 6> elastic_stress_pa{};  // S_e(Fe) of the committed step
  Eigen::Matrix3d inverse_plastic_deformation = Eigen::Matrix3d::Identity();  // Fp⁻¹, det = 1
  double equivalent_plastic_strain = 0.0;
  // Time spent above the yield limit (time hardening); it holds, not resets, below the limit.
  double yield_clock_s = 0.0;
  // σ_max(Fp⁻¹)², 1 at rest: how much the flow has stiffened the element. Its stiffness is
  // ∇Nᵀ·Fp⁻¹·C·Fp⁻ᵀ·∇N, so its highest frequency² is at most this times that of its unflowed
  // shape (the explicit step takes it: stiffening_since_rest).
  double flow_stiffening = 1.0;
};

// The flow stops where it has stiffened an element by this much (kFlowStiffening), a plastic
// stretch of 4 along or of ½ across it: tissue drawn further would tear, which is not modelled,
// and an element flowed on into a needle (a lifted specimen's neck drawn out ninefold) outgrew
// any step. Past it the element answers elastically: it does not flow back either (a flow that
// would lower its stiffening is not told apart), a simplification of this limit.
inline constexpr double kMaxFlowStiffening = 4.0;

// The committed history of every element of a mesh, stored component by component in blocks of
// kBlock elements (component k of element e at block(e)[k·kBlock + e % kBlock]) so that the
// element loops read and write several elements per vector instruction, each component of a
// block at a fixed offset from one pointer. The components are ViscousTissueState's fields in
// order: H [0, 6), S_e [6, 12) in Voigt order, Fp⁻¹ column-major [12, 21), the equivalent plastic
// strain, the yield clock and the flow's stiffening.
class ViscousHistory {
 public:
  static constexpr std::size_t kBlock = 64;
  static constexpr int kMaxwellStress = 0;
  static constexpr int kElasticStress = 6;
  static constexpr int kInversePlasticDeformation = 12;
  static constexpr int kEquivalentPlasticStrain = 21;
  static constexpr int kYieldClock = 22;
  static constexpr int kFlowStiffening = 23;  // ViscousTissueState::flow_stiffening
  static constexpr int kComponents = 24;

  ViscousHistory() = default;
  // `elements` histories at rest: no stress, Fp = I.
  explicit ViscousHistory(std::size_t elements);

  std::size_t size() const { return elements_; }
  std::size_t capacity_bytes() const { return values_.capacity() * sizeof(double); }

  ViscousTissueState load(std::size_t e) const;
  void store(std::size_t e, const ViscousTissueState& history);
  Eigen::Matrix3d inverse_plastic_deformation(std::size_t e) const;
  Voigt6 maxwell_stress_pa(std::size_t e) const;
  double equivalent_plastic_strain(std::size_t e) const {
    return value(kEquivalentPlasticStrain, e);
  }
  // The largest kFlowStiffening of all elements (1 where none has flowed). Reads the blocks that
  // have flowed only.
  double largest_flow_stiffening() const;

  double value(int k, std::size_t e) const {
    return values_[(e / kBlock * kComponents + k) * kBlock + e % kBlock];
  }
  // Element from_e's whole history in `from` becomes element to_e's here.
  void copy_element(const ViscousHistory& from, std::size_t from_e, std::size_t to_e);
  // The block holding element e. The element loops write the arm and elastic stress through it,
  // never Fp⁻¹ (which goes through store(), for plastic_blocks).
  double* block(std::size_t e) { return values_.data() + e / kBlock * kComponents * kBlock; }
  // Per block of kBlock elements: 1 once an element of it has stored Fp ≠ I. Blocks with 0 skip
  // the products with Fp⁻¹ (most tissue never yields).
  const std::uint8_t* plastic_blocks() const { return plastic_blocks_.data(); }

  // Simulated time since the plastic flow was last taken (SimModel::plastic_flow_interval_s).
  double flow_pending_s = 0.0;

  bool operator==(const ViscousHistory&) const = default;

 private:
  double& slot(int k, std::size_t e) { return block(e)[k * kBlock + e % kBlock]; }
  void note_flow(std::size_t e);  // flags e's block if e's Fp⁻¹ is not the identity

  std::size_t elements_ = 0;
  std::vector<double> values_;
  std::vector<std::uint8_t> plastic_blocks_;
};

// First Piola–Kirchhoff stress P (Pa) at deformation gradient F, `step.dt_s` after the state
// `committed`. Writes the state that committing F would keep to `trial` (which may be `committed`
// itself); reads nothing else, so the stages of a Runge–Kutta step can evaluate trial
// deformations from the same committed state. Allocates nothing. Finite for every finite F,
// including det F ≤ 0: below J = neo_hookean::kMinVolumeRatio the Maxwell arm is not fed (its
// 2nd Piola–Kirchhoff elastic stress grows like C⁻¹ without bound as J → 0), it only relaxes, and
// there is no plastic flow. `yield_raise_pa` raises the yield limit of this element: the stress it
// bears in vivo (SimModel::in_vivo_stress_pa), which its yield is measured above.
Eigen::Matrix3d viscous_tissue_stress(const Eigen::Matrix3d& F, const ViscousTissueStep& step,
                                      const ViscousTissueState& committed,
                                      ViscousTissueState& trial, double yield_raise_pa = 0.0);

// viscous_tissue_stress, committing the step into `state`.
Eigen::Matrix3d viscous_tissue_update(const Eigen::Matrix3d& F, const ViscousTissueStep& step,
                                      ViscousTissueState& state, double yield_raise_pa = 0.0);

// The Maxwell arm as an ODE, for integrators that carry it in their own state (Runge–Kutta stages,
// implicit solves), so that it advances with the scheme's own order. With Q = S_e − H (H the arm
// variable above): Q̇ = (S_e(F_e) − Q)/τ and S̄ = S_e − g1·Q. No strain rate is needed, and the
// exponential update above is this ODE's exact solution for S_e linear in time.
//
// The arm's Q at the evaluation is keep·q_known + elastic_weight·S_e(F_e): (1, 0) for an explicit
// stage at q_known; (1/(1+θ), θ/(1+θ)) for an implicit step, θ = β/τ, q_known the predictor (Q_n
// for backward Euler). Fp is held at `fp_inverse`. Writes S_e to `elastic_stress` (for the rate
// and the commit) and returns P. Below J = neo_hookean::kMinVolumeRatio the arm is frozen (Q as
// known, S_e reported as Q so that Q̇ = 0), as the incremental update does. Allocates nothing.
Eigen::Matrix3d viscoelastic_stress_rate_form(const Eigen::Matrix3d& F,
                                              const ViscousTissueStep& step,
                                              const Eigen::Matrix3d& fp_inverse,
                                              const Voigt6& q_known, double keep,
                                              double elastic_weight, Voigt6& elastic_stress);

// ∂P/∂F of viscoelastic_stress_rate_form at the same arguments, 9×9 over row-major indices.
Eigen::Matrix<double, 9, 9> viscoelastic_stress_tangent_rate_form(
    const Eigen::Matrix3d& F, const ViscousTissueStep& step, const Eigen::Matrix3d& fp_inverse,
    const Voigt6& q_known, double keep, double elastic_weight);

// A homogeneous material point under uniaxial stress: F = diag(λ_axial, λ_lateral, λ_lateral),
// the lateral stretch solved by Newton's method so that the lateral stresses vanish. For
// verification against the seed's 1-D formulas and for material curves.
class UniaxialDriver {
 public:
  // Throws std::invalid_argument with validate's message for invalid parameters. The step
  // functions throw std::runtime_error if Newton's method does not converge in 50 iterations.
  explicit UniaxialDriver(const ViscousTissueParameters& parameters);

  // Holds the axial stretch over a step of dt_s (0: an instantaneous jump) and commits it.
  // Returns the nominal axial stress P_xx (force per reference area) in Pa.
  double step_to_stretch(double axial_stretch, double dt_s);
  // Holds the nominal axial stress over a step of dt_s and commits it. Returns the axial stretch.
  double step_to_nominal_stress(double nominal_stress_pa, double dt_s);

  double axial_stretch() const { return axial_stretch_; }
  double lateral_stretch() const { return lateral_stretch_; }
  const ViscousTissueState& state() const { return state_; }

 private:
  ViscousTissueParameters parameters_;
  ViscousTissueState state_;
  double axial_stretch_ = 1.0;
  double lateral_stretch_ = 1.0;
};

}  // namespace liversim
