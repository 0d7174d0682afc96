#include "liversim/engine/fibres.h"

#include <cmath>
#include <sstream>

namespace liversim {

std::optional<std::string> validate(const FibreParameters& fibres) {
  std::ostringstream message;
  if (!std::isfinite(fibres.k1_pa) || fibres.k1_pa < 0.0) {
    message << "fibre stiffness k1 = " << fibres.k1_pa
            << " Pa is invalid: expected a finite value >= 0";
    return message.str();
  }
  if (!std::isfinite(fibres.k2) || fibres.k2 < 0.0) {
    message << "fibre exponent k2 = " << fibres.k2 << " is invalid: expected a finite value >= 0";
    return message.str();
  }
  return std::nullopt;
}

namespace hgo {
namespace {

// e(x) = exp(x), continued linearly past kMaxExponent; and its derivative.
double guarded_exp(double x) {
  return x <= kMaxExponent ? std::exp(x) : std::exp(kMaxExponent) * (1.0 + x - kMaxExponent);
}
double guarded_exp_slope(double x) {
  return std::exp(std::min(x, kMaxExponent));
}

double fibre_invariant(const Eigen::Matrix3d& F, const Eigen::Vector3d& a) {
  return (F * a).squaredNorm();
}

}  // namespace

double energy_density(const Eigen::Matrix3d& F, const Eigen::Vector3d& a,
                      const FibreParameters& p) {
  const double stretch = fibre_invariant(F, a) - 1.0;
  if (stretch <= 0.0 || p.k1_pa == 0.0) return 0.0;
  // k2 → 0 limit: k1/2 (I4 − 1)², a linear fibre.
  if (p.k2 < 1e-12) return 0.5 * p.k1_pa * stretch * stretch;
  return p.k1_pa / (2.0 * p.k2) * (guarded_exp(p.k2 * stretch * stretch) - 1.0);
}

Eigen::Matrix3d first_piola_stress(const Eigen::Matrix3d& F, const Eigen::Vector3d& a,
                                   const FibreParameters& p) {
  const Eigen::Vector3d fa = F * a;
  const double stretch = fa.squaredNorm() - 1.0;
  if (stretch <= 0.0 || p.k1_pa == 0.0) return Eigen::Matrix3d::Zero();
  const double psi4 = p.k1_pa * stretch * guarded_exp_slope(p.k2 * stretch * stretch);
  return 2.0 * psi4 * fa * a.transpose();
}

Eigen::Matrix<double, 9, 9> stress_tangent(const Eigen::Matrix3d& F, const Eigen::Vector3d& a,
                                           const FibreParameters& p) {
  Eigen::Matrix<double, 9, 9> tangent = Eigen::Matrix<double, 9, 9>::Zero();
  const Eigen::Vector3d fa = F * a;
  const double stretch = fa.squaredNorm() - 1.0;
  if (stretch <= 0.0 || p.k1_pa == 0.0) return tangent;
  const double x = p.k2 * stretch * stretch;
  const double e = guarded_exp_slope(x);
  const double psi4 = p.k1_pa * stretch * e;
  const double psi44 = p.k1_pa * e * (1.0 + (x <= kMaxExponent ? 2.0 * x : 0.0));
  Eigen::Matrix<double, 9, 1> g;  // ∂I4/∂F / 2 = (Fa) ⊗ a, flattened
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J) {
      g[3 * i + J] = fa[i] * a[J];
      for (int L = 0; L < 3; ++L) tangent(3 * i + J, 3 * i + L) += 2.0 * psi4 * a[J] * a[L];
    }
  tangent += 4.0 * psi44 * g * g.transpose();
  return tangent;
}

double tangent_modulus_pa(const Eigen::Matrix3d& F, const Eigen::Vector3d& a,
                          const FibreParameters& p) {
  const double i4 = fibre_invariant(F, a);
  const double stretch = i4 - 1.0;
  if (stretch <= 0.0 || p.k1_pa == 0.0) return 0.0;
  const double x = p.k2 * stretch * stretch;
  const double e = guarded_exp_slope(x);
  const double psi4 = p.k1_pa * stretch * e;
  // ψ44 = k1 e (1 + 2 k2 (I4−1)²) below the guard; the linear continuation has a smaller one.
  const double psi44 = p.k1_pa * e * (1.0 + (x <= kMaxExponent ? 2.0 * x : 0.0));
  return 2.0 * psi4 + 4.0 * i4 * psi44;
}

}  // namespace hgo
}  // namespace liversim
