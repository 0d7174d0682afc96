// Implicit schemes: backward Euler and BDF2 on M·v̇ = f(x, Q, v) − αM·v, ẋ = v, solved for the
// end-of-step positions by Newton's method with the sparse tangent in a fixed pattern and a
// sparse LDLᵀ factorisation (symbolic analysis once per state).
//
// Both schemes read  x₁ = x̂ + β·v₁,  v₁ = v̂ + β·a₁  with β = Δt, x̂ = xₙ, v̂ = vₙ for backward Euler
// and β = 2Δt/3, x̂ = (4xₙ − xₙ₋₁)/3, v̂ = (4vₙ − vₙ₋₁)/3 for BDF2, so Newton solves
//   r(x₁) = M·(v₁ − v̂)/β + αM·v₁ − f(x₁, v₁) = 0,  v₁ = (x₁ − x̂)/β,
// with Jacobian M/β² + (αM + C)/β + K. The Maxwell arm follows the same rule in closed form per
// element: Q₁ = (Q̂ + θ·S_e(x₁))/(1 + θ), θ = β/τ.

#include "integrator_internal.h"

#include "sparse_ldlt.h"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>

#include <array>
#include <limits>

namespace liversim {

class ImplicitSolver {
 public:
  explicit ImplicitSolver(const SimModel& model);

  // The Newton matrix, upper triangle in compressed columns, in a fill-reducing (AMD) order of
  // the unknowns; fixed degrees of freedom keep only a unit diagonal.
  Eigen::SparseMatrix<double> matrix;
  // Per element, the value index of each of its 12×12 entries that lands in the upper triangle
  // (−1: its transpose does, or a fixed degree of freedom).
  std::vector<int> element_entry;
  std::vector<int> diagonal_entry;  // per degree of freedom 3·node + axis
  std::vector<int> ordered_index;   // position of each degree of freedom in the factorised order
  detail::SparseLdlt factorisation;
  std::vector<double> rhs, ordered_rhs;
  NodeArray force;
  // Newton–Krylov: the residual, the correction, the Krylov basis (kKrylovDimension + 1 vectors)
  // and the perturbed state of the Jacobian-vector products.
  std::vector<double> residual, correction, krylov_basis, krylov_work, perturbed_residual;
  NodeArray perturbed_position_m, perturbed_velocity_m_per_s;
};

namespace {
constexpr int kKrylovDimension = 30;
// Relative residual of the Newton equation at which GMRES stops: inexact Newton, whose
// contraction per iteration is then about this (plus the quadratic term).
constexpr double kKrylovTolerance = 1e-4;
// A factorisation is rebuilt once a Newton solve needs this many Krylov iterations more than the
// first solve on it did. The count is not compared with a fixed bound: the assembled tangent
// leaves average nodal pressure out, so even a fresh factorisation may need 9 iterations on a fine
// mesh, and rebuilding it (a third of a second at 10 k tetrahedra) would buy nothing.
constexpr int kKrylovGrowthBeforeRefactor = 4;
}  // namespace

ImplicitSolver::ImplicitSolver(const SimModel& model) {
  const auto dofs = static_cast<int>(3 * model.node_count);
  auto dof = [&](std::size_t e, int local) {
    return 3 * static_cast<int>(model.corner[local / 3][e]) + local % 3;
  };
  auto free = [&](int d) { return !model.is_fixed[static_cast<std::size_t>(d / 3)]; };

  // Fill-reducing order from the symmetric pattern.
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(model.tet_count * 144 + static_cast<std::size_t>(dofs));
  for (int d = 0; d < dofs; ++d) triplets.emplace_back(d, d, 1.0);
  for (std::size_t e = 0; e < model.tet_count; ++e)
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < 12; ++j)
        if (free(dof(e, i)) && free(dof(e, j))) triplets.emplace_back(dof(e, i), dof(e, j), 1.0);
  Eigen::SparseMatrix<double> pattern(dofs, dofs);
  pattern.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> inverse_order;
  Eigen::AMDOrdering<int>()(pattern.selfadjointView<Eigen::Lower>(), inverse_order);
  const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> order =
      inverse_order.inverse();
  ordered_index.assign(order.indices().data(), order.indices().data() + dofs);

  for (auto& t : triplets) {
    const int r = ordered_index[static_cast<std::size_t>(t.row())];
    const int c = ordered_index[static_cast<std::size_t>(t.col())];
    t = Eigen::Triplet<double>(std::min(r, c), std::max(r, c), 0.0);
  }
  matrix.resize(dofs, dofs);
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  matrix.makeCompressed();

  auto entry_of = [&](int row, int col) {
    const int* begin = matrix.innerIndexPtr() + matrix.outerIndexPtr()[col];
    const int* end = matrix.innerIndexPtr() + matrix.outerIndexPtr()[col + 1];
    const int* found = std::lower_bound(begin, end, row);
    return found != end && *found == row ? static_cast<int>(found - matrix.innerIndexPtr()) : -1;
  };
  element_entry.assign(model.tet_count * 144, -1);
  for (std::size_t e = 0; e < model.tet_count; ++e)
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < 12; ++j) {
        if (!free(dof(e, i)) || !free(dof(e, j))) continue;
        const int row = ordered_index[static_cast<std::size_t>(dof(e, i))];
        const int col = ordered_index[static_cast<std::size_t>(dof(e, j))];
        if (row <= col)
          element_entry[e * 144 + static_cast<std::size_t>(i * 12 + j)] = entry_of(row, col);
      }
  diagonal_entry.resize(static_cast<std::size_t>(dofs));
  for (int d = 0; d < dofs; ++d) {
    const int at = ordered_index[static_cast<std::size_t>(d)];
    diagonal_entry[static_cast<std::size_t>(d)] = entry_of(at, at);
  }
  const std::span<const int> columns(matrix.outerIndexPtr(), static_cast<std::size_t>(dofs) + 1);
  const std::span<const int> rows(matrix.innerIndexPtr(),
                                  static_cast<std::size_t>(matrix.nonZeros()));
  factorisation.analyse(columns, rows);
  const auto size = static_cast<std::size_t>(dofs);
  rhs.resize(size);
  ordered_rhs.resize(size);
  force.resize(model.node_count);
  residual.resize(size);
  correction.resize(size);
  krylov_basis.resize((kKrylovDimension + 1) * size);
  krylov_work.resize(size);
  perturbed_residual.resize(size);
  perturbed_position_m.resize(model.node_count);
  perturbed_velocity_m_per_s.resize(model.node_count);
}

ImplicitSolverHandle::ImplicitSolverHandle() = default;
ImplicitSolverHandle::ImplicitSolverHandle(const ImplicitSolverHandle&) {}
ImplicitSolverHandle& ImplicitSolverHandle::operator=(const ImplicitSolverHandle& other) {
  if (this != &other) solver.reset();
  return *this;
}
ImplicitSolverHandle::ImplicitSolverHandle(ImplicitSolverHandle&&) noexcept = default;
ImplicitSolverHandle& ImplicitSolverHandle::operator=(ImplicitSolverHandle&&) noexcept = default;
ImplicitSolverHandle::~ImplicitSolverHandle() = default;

namespace detail {

void prepare_implicit_solver(const SimModel& model, ImplicitSolverHandle& handle) {
  handle.solver = std::make_unique<ImplicitSolver>(model);
}

namespace {

// Assembles M/β² + (αM + C)/β + K_springs + K(x) into the solver's matrix.
void assemble(const SimModel& model, const SimState& state, const StepInputs& inputs,
              const ViscousArmInputs& arm, double beta, ImplicitSolver& solver) {
  double* values = solver.matrix.valuePtr();
  std::fill(values, values + solver.matrix.nonZeros(), 0.0);
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    const Eigen::Matrix3d dm_inverse = element_dm_inverse(model, e);
    const Eigen::Matrix3d F = deformation_gradient(model, state.position_m, e);
    const Eigen::Matrix<double, 9, 9> tangent = element_step_tangent(model, state, arm, e, F);
    // Reference shape-function gradients as columns: corners 1–3 are the rows of Dm⁻¹.
    Eigen::Matrix<double, 3, 4> gradients;
    gradients.rightCols<3>() = dm_inverse.transpose();
    gradients.col(0) = -gradients.rightCols<3>().rowwise().sum();
    const double volume = model.rest_volume_m3[e];
    const int* entries = &solver.element_entry[e * 144];
    // K_ab[i][k] = V·Σ_JL ∂N_a/∂X_J · ∂P_iJ/∂F_kL · ∂N_b/∂X_L.
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) {
        const Eigen::Matrix<double, 4, 4> block =
            volume * gradients.transpose() * tangent.block<3, 3>(3 * i, 3 * k) * gradients;
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) {
            const int entry = entries[(3 * a + i) * 12 + 3 * b + k];
            if (entry >= 0) values[entry] += block(a, b);
          }
      }
  }
  for (std::size_t n = 0; n < model.node_count; ++n) {
    const double mass = model.lumped_mass_kg[n];
    const double diagonal =
        model.is_fixed[n] ? 1.0 : mass / (beta * beta) + model.mass_damping_per_s * mass / beta;
    for (int axis = 0; axis < 3; ++axis)
      values[solver.diagonal_entry[3 * n + static_cast<std::size_t>(axis)]] += diagonal;
  }
  for (const auto& spring : inputs.springs) {
    if (model.is_fixed[spring.node]) continue;
    for (int axis = 0; axis < 3; ++axis)
      values[solver.diagonal_entry[3 * spring.node + static_cast<std::size_t>(axis)]] +=
          spring.stiffness_n_per_m + spring.damping_n_s_per_m / beta;
  }
}

// GMRES on J·δ = −r (r in solver.residual, evaluated at x), right-preconditioned by the
// factorised tangent P, with J·u ≈ (r(x + εu) − r(x))/ε. Writes δ; returns the iterations used.
// Allocates nothing (the basis is the solver's).
template <typename Residual, typename Precondition>
int solve_newton_equation(const SimModel& model, ImplicitSolver& solver, Residual& residual,
                          Precondition& precondition, const NodeArray& x,
                          std::vector<double>& delta) {
  const std::size_t size = solver.residual.size();
  auto basis = [&](int j) {
    return solver.krylov_basis.data() + static_cast<std::size_t>(j) * size;
  };
  const std::vector<double>& r0 = solver.residual;
  double beta0 = 0.0;
  for (double value : r0) beta0 += value * value;
  beta0 = std::sqrt(beta0);
  std::fill(delta.begin(), delta.end(), 0.0);
  if (!(beta0 > 0.0)) return 0;
  for (std::size_t i = 0; i < size; ++i) basis(0)[i] = -r0[i] / beta0;

  std::array<double, (kKrylovDimension + 1) * kKrylovDimension> h{};
  auto H = [&](int i, int j) -> double& {
    return h[static_cast<std::size_t>(i * kKrylovDimension + j)];
  };
  std::array<double, kKrylovDimension> cs{}, sn{};
  std::array<double, kKrylovDimension + 1> g{};
  g[0] = beta0;
  // A perturbation of a millionth of the smallest element: far inside the force's nonlinearity,
  // far above its round-off.
  const double perturbation_m = 1e-6 * model.min_element_height_m;
  std::vector<double>& z = solver.krylov_work;
  int k = 0;
  for (int j = 0; j < kKrylovDimension; ++j) {
    std::copy(basis(j), basis(j) + size, z.begin());
    precondition(z);
    double largest = 0.0;
    for (double value : z) largest = std::max(largest, std::abs(value));
    if (!(largest > 0.0) || !std::isfinite(largest)) break;
    const double eps = perturbation_m / largest;
    NodeArray& xp = solver.perturbed_position_m;
    for (std::size_t n = 0; n < model.node_count; ++n) {
      xp.x[n] = x.x[n] + eps * z[3 * n];
      xp.y[n] = x.y[n] + eps * z[3 * n + 1];
      xp.z[n] = x.z[n] + eps * z[3 * n + 2];
    }
    residual(xp, solver.perturbed_velocity_m_per_s, solver.perturbed_residual);
    double* w = basis(j + 1);
    for (std::size_t i = 0; i < size; ++i) w[i] = (solver.perturbed_residual[i] - r0[i]) / eps;
    for (int i = 0; i <= j; ++i) {  // modified Gram–Schmidt
      double dot = 0.0;
      const double* vi = basis(i);
      for (std::size_t l = 0; l < size; ++l) dot += w[l] * vi[l];
      H(i, j) = dot;
      for (std::size_t l = 0; l < size; ++l) w[l] -= dot * vi[l];
    }
    double norm = 0.0;
    for (std::size_t l = 0; l < size; ++l) norm += w[l] * w[l];
    norm = std::sqrt(norm);
    H(j + 1, j) = norm;
    for (int i = 0; i < j; ++i) {  // earlier rotations on the new column
      const double upper = cs[i] * H(i, j) + sn[i] * H(i + 1, j);
      H(i + 1, j) = -sn[i] * H(i, j) + cs[i] * H(i + 1, j);
      H(i, j) = upper;
    }
    const double radius = std::hypot(H(j, j), H(j + 1, j));
    if (!(radius > 0.0)) break;
    cs[j] = H(j, j) / radius;
    sn[j] = H(j + 1, j) / radius;
    H(j, j) = radius;
    H(j + 1, j) = 0.0;
    g[j + 1] = -sn[j] * g[j];
    g[j] = cs[j] * g[j];
    k = j + 1;
    if (std::abs(g[j + 1]) <= kKrylovTolerance * beta0 || norm == 0.0) break;
    for (std::size_t l = 0; l < size; ++l) w[l] /= norm;
  }
  // y from the triangular system, then δ = P⁻¹·Σ yᵢ·vᵢ.
  std::array<double, kKrylovDimension> y{};
  for (int i = k - 1; i >= 0; --i) {
    double sum = g[i];
    for (int l = i + 1; l < k; ++l) sum -= H(i, l) * y[l];
    y[i] = sum / H(i, i);
  }
  for (int i = 0; i < k; ++i) {
    const double* vi = basis(i);
    for (std::size_t l = 0; l < size; ++l) delta[l] += y[i] * vi[l];
  }
  precondition(delta);
  return k;
}

}  // namespace

void advance_implicit(const SimModel& model, SimState& state, const StepInputs& inputs,
                      double interval_s, StepReport& report) {
  IntegratorScratch& s = state.integrator;
  if (!s.implicit.solver) prepare_implicit_solver(model, s.implicit);  // a copied state
  ImplicitSolver& solver = *s.implicit.solver;
  const auto dofs = static_cast<std::size_t>(solver.matrix.cols());
  const std::span<const int> columns(solver.matrix.outerIndexPtr(), dofs + 1);
  const std::span<const int> rows(solver.matrix.innerIndexPtr(),
                                  static_cast<std::size_t>(solver.matrix.nonZeros()));
  const std::span<const double> values(solver.matrix.valuePtr(), rows.size());
  const IntegratorSettings& settings = model.integrator;
  const double steps = steps_to_cover(interval_s, settings.step_s * s.step_scale);
  const double dt = interval_s / steps;
  const std::size_t n_nodes = model.node_count;

  for (int step = 0; step < static_cast<int>(steps); ++step) {
    // BDF2 needs the previous step at the same length; otherwise (first step, changed step) the
    // step is backward Euler, which keeps the global order 2.
    // A change of inputs is a kink in time that BDF2's history would smooth over (a first-order
    // error at every change): restart there too.
    const bool bdf2 = settings.kind == IntegratorKind::bdf2 && s.has_previous &&
                      std::abs(s.previous_step_s - dt) <= 1e-9 * dt &&
                      !(step == 0 && s.inputs_changed);
    const double beta = bdf2 ? 2.0 * dt / 3.0 : dt;
    arm_of_committed_state(model, state, s.start_arm);
    auto& x = state.position_m;
    auto& v = state.velocity_m_per_s;
    for (std::size_t n = 0; n < n_nodes; ++n) {
      if (bdf2) {
        s.predicted_position_m.x[n] = (4.0 * x.x[n] - s.previous_position_m.x[n]) / 3.0;
        s.predicted_position_m.y[n] = (4.0 * x.y[n] - s.previous_position_m.y[n]) / 3.0;
        s.predicted_position_m.z[n] = (4.0 * x.z[n] - s.previous_position_m.z[n]) / 3.0;
        s.predicted_velocity_m_per_s.x[n] = (4.0 * v.x[n] - s.previous_velocity_m_per_s.x[n]) / 3.0;
        s.predicted_velocity_m_per_s.y[n] = (4.0 * v.y[n] - s.previous_velocity_m_per_s.y[n]) / 3.0;
        s.predicted_velocity_m_per_s.z[n] = (4.0 * v.z[n] - s.previous_velocity_m_per_s.z[n]) / 3.0;
      } else {
        s.predicted_position_m.x[n] = x.x[n];
        s.predicted_position_m.y[n] = x.y[n];
        s.predicted_position_m.z[n] = x.z[n];
        s.predicted_velocity_m_per_s.x[n] = v.x[n];
        s.predicted_velocity_m_per_s.y[n] = v.y[n];
        s.predicted_velocity_m_per_s.z[n] = v.z[n];
      }
    }
    if (model.effects.viscous) {
      for (std::size_t e = 0; e < s.start_arm.size(); ++e)
        for (int k = 0; k < 6; ++k)
          s.predicted_arm[e][k] =
              bdf2 ? (4.0 * s.start_arm[e][k] - s.previous_arm[e][k]) / 3.0 : s.start_arm[e][k];
      for (std::size_t r = 0; r < model.viscous_parameters.size(); ++r) {
        if (!model.viscous_parameters[r]) continue;
        const double theta = beta / model.viscous_parameters[r]->viscoelastic.relaxation_time_s();
        s.keep_by_region[r] = 1.0 / (1.0 + theta);
        s.elastic_weight_by_region[r] = theta / (1.0 + theta);
      }
      std::swap(s.previous_arm, s.start_arm);  // Q_{n} becomes the previous step's
    }
    s.previous_position_m = x;
    s.previous_velocity_m_per_s = v;
    s.has_previous = true;
    s.previous_step_s = dt;

    // Start Newton from the predictor's free flight: x̂ + β·v̂.
    for (std::size_t n = 0; n < n_nodes; ++n) {
      x.x[n] = s.predicted_position_m.x[n] + beta * s.predicted_velocity_m_per_s.x[n];
      x.y[n] = s.predicted_position_m.y[n] + beta * s.predicted_velocity_m_per_s.y[n];
      x.z[n] = s.predicted_position_m.z[n] + beta * s.predicted_velocity_m_per_s.z[n];
    }
    const ViscousArmInputs arm{s.predicted_arm, s.keep_by_region, s.elastic_weight_by_region,
                               s.elastic_stress};
    // r(x) into `r` (DOF order, 0 on fixed DOFs), velocities v = (x − x̂)/β into `velocity`.
    auto residual = [&](const NodeArray& position, NodeArray& velocity, std::vector<double>& r) {
      for (std::size_t n = 0; n < n_nodes; ++n) {
        velocity.x[n] = (position.x[n] - s.predicted_position_m.x[n]) / beta;
        velocity.y[n] = (position.y[n] - s.predicted_position_m.y[n]) / beta;
        velocity.z[n] = (position.z[n] - s.predicted_position_m.z[n]) / beta;
      }
      const ElasticEvaluation seen =
          compute_internal_forces_rate_form(model, state, position, arm, solver.force);
      ++report.force_evaluations;
      add_input_forces(model, inputs, position, velocity, solver.force);
      for (std::size_t n = 0; n < n_nodes; ++n) {
        const double mass = model.lumped_mass_kg[n];
        const bool fixed = model.is_fixed[n] != 0;
        const double inertia = mass / beta, damping = model.mass_damping_per_s * mass;
        const double* vp[3] = {&velocity.x[n], &velocity.y[n], &velocity.z[n]};
        const double* hat[3] = {&s.predicted_velocity_m_per_s.x[n],
                                &s.predicted_velocity_m_per_s.y[n],
                                &s.predicted_velocity_m_per_s.z[n]};
        const double* f[3] = {&solver.force.x[n], &solver.force.y[n], &solver.force.z[n]};
        for (int a = 0; a < 3; ++a)
          r[3 * n + static_cast<std::size_t>(a)] =
              fixed ? 0.0 : inertia * (*vp[a] - *hat[a]) + damping * *vp[a] - *f[a];
      }
      return seen;
    };
    // M⁻¹-like solve with the factorised approximate tangent, in place on a DOF-order vector.
    auto precondition = [&](std::vector<double>& vector) {
      for (std::size_t d = 0; d < dofs; ++d)
        solver.ordered_rhs[static_cast<std::size_t>(solver.ordered_index[d])] = vector[d];
      solver.factorisation.solve(solver.ordered_rhs);
      for (std::size_t d = 0; d < dofs; ++d)
        vector[d] = solver.ordered_rhs[static_cast<std::size_t>(solver.ordered_index[d])];
      ++report.linear_solves;
    };

    bool converged = false;
    // The tangent changes slowly, and the Krylov solve below absorbs what it misses: keep a
    // factorisation across iterations and steps, and build a new one for a quite different β,
    // new springs, or once the Krylov solve needs clearly more iterations than it did on the
    // fresh factorisation.
    // (BDF2's restarts switch β between Δt and 2Δt/3: GMRES absorbs that much.)
    auto drifted = [&](int krylov) {
      return s.fresh_krylov_iterations > 0 &&
             krylov > s.fresh_krylov_iterations + kKrylovGrowthBeforeRefactor;
    };
    bool refactor = !s.factorisation_valid || std::abs(beta / s.factorised_beta_s - 1.0) > 0.6 ||
                    drifted(s.last_newton_iterations) ||
                    (step == 0 && s.inputs_changed && !inputs.springs.empty());
    int krylov_iterations = 0;
    double last_correction = std::numeric_limits<double>::infinity();
    for (int iteration = 0; iteration <= settings.max_newton_iterations; ++iteration) {
      const ElasticEvaluation seen = residual(x, v, solver.residual);
      report.max_stiffening = std::max(report.max_stiffening, stiffening_since_rest(model, seen));
      if (last_correction <= settings.newton_tolerance_m) {
        converged = true;  // the residual (and the arm's S_e) is now that of the final x
        break;
      }
      if (iteration == settings.max_newton_iterations) break;
      if (refactor) {
        assemble(model, state, inputs, arm, beta, solver);
        ++report.factorizations;
        s.factorisation_valid = solver.factorisation.factorise(columns, rows, values);
        s.factorised_beta_s = beta;
        s.fresh_krylov_iterations = 0;
        refactor = false;
        if (!s.factorisation_valid) break;
      }
      ++report.newton_iterations;
      // Newton's equation J·δ = −r by GMRES, right-preconditioned with the factorised tangent, J·u
      // by a difference of residuals: the true Jacobian, average nodal pressure included (the
      // assembled tangent leaves its coupling out, and alone converges slowly or not at all).
      const int used =
          solve_newton_equation(model, solver, residual, precondition, x, solver.correction);
      krylov_iterations = std::max(krylov_iterations, used);
      if (s.fresh_krylov_iterations == 0) s.fresh_krylov_iterations = used;
      if (drifted(used)) refactor = true;
      double largest_sq = 0.0;
      for (std::size_t n = 0; n < n_nodes; ++n) {
        const double dx = solver.correction[3 * n], dy = solver.correction[3 * n + 1],
                     dz = solver.correction[3 * n + 2];
        x.x[n] += dx;
        x.y[n] += dy;
        x.z[n] += dz;
        largest_sq = std::max(largest_sq, dx * dx + dy * dy + dz * dz);
      }
      last_correction = std::sqrt(largest_sq);
      if (!std::isfinite(last_correction)) break;
    }
    s.last_newton_iterations = krylov_iterations;
    if (!converged) ++report.unconverged_steps;
    for (std::size_t n = 0; n < n_nodes; ++n) {
      v.x[n] = (x.x[n] - s.predicted_position_m.x[n]) / beta;
      v.y[n] = (x.y[n] - s.predicted_position_m.y[n]) / beta;
      v.z[n] = (x.z[n] - s.predicted_position_m.z[n]) / beta;
    }
    if (model.effects.viscous) {
      for (std::size_t e = 0; e < s.stage_arm.size(); ++e) {
        const auto r = static_cast<std::size_t>(model.region[e]);
        for (int k = 0; k < 6; ++k)
          s.stage_arm[e][k] = s.keep_by_region[r] * s.predicted_arm[e][k] +
                              s.elastic_weight_by_region[r] * s.elastic_stress[e][k];
      }
      commit_arm(model, state, x, s.stage_arm, dt);
    }
    note_error_estimate(report, history_error_estimate(model, s, v, dt, settings.kind));
    state.max_speed_m_per_s = largest_norm(v);
    state.last_step_s = dt;
    state.time_s += dt;
    ++state.step_count;
    ++report.substeps;
    report.smallest_substep_s = std::min(report.smallest_substep_s, dt);
    report.largest_substep_s = std::max(report.largest_substep_s, dt);
  }
}

}  // namespace detail
}  // namespace liversim
