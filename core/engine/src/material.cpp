#include "liversim/engine/material.h"
#include "liversim/engine/validation_message.h"

#include <Eigen/Geometry>

#include <cmath>

namespace liversim {

std::optional<std::string> validate(const TissueMaterial& material) {
  const auto& out_of_range = out_of_range_message;
  if (!std::isfinite(material.youngs_modulus_pa) || material.youngs_modulus_pa <= 0.0)
    return out_of_range("Young's modulus (Pa)", material.youngs_modulus_pa, "a finite value > 0");
  if (!std::isfinite(material.poisson_ratio) || material.poisson_ratio <= -1.0 ||
      material.poisson_ratio >= 0.5)
    return out_of_range("Poisson's ratio", material.poisson_ratio, "a value in (-1, 0.5)");
  if (!std::isfinite(material.density_kg_per_m3) || material.density_kg_per_m3 <= 0.0)
    return out_of_range("density (kg/m³)", material.density_kg_per_m3, "a finite value > 0");
  if (!std::isfinite(material.mooney_rivlin_fraction) || material.mooney_rivlin_fraction < 0.0 ||
      material.mooney_rivlin_fraction >= 1.0)
    return out_of_range("Mooney-Rivlin fraction c2/(c1+c2)", material.mooney_rivlin_fraction,
                        "a value in [0, 1)");
  // The I2 term's share of λ (4 c2 = 2 f μ) must leave the volumetric λ positive.
  if (material.mooney_rivlin_fraction > 0.0 &&
      material.lame_lambda_pa() -
              2.0 * material.mooney_rivlin_fraction * material.shear_modulus_pa() <=
          0.0)
    return out_of_range("Mooney-Rivlin fraction c2/(c1+c2)", material.mooney_rivlin_fraction,
                        "a value below λ/(2μ) = ν/(1 − 2ν) for this Poisson's ratio");
  return std::nullopt;
}

Eigen::Matrix3d cofactor(const Eigen::Matrix3d& F) {
  Eigen::Matrix3d c;
  c.col(0) = F.col(1).cross(F.col(2));
  c.col(1) = F.col(2).cross(F.col(0));
  c.col(2) = F.col(0).cross(F.col(1));
  return c;  // columns of cof(F) are the cross products of the other two columns of F
}

void add_cofactor_derivative(const Eigen::Matrix3d& F, double scale,
                             Eigen::Matrix<double, 9, 9>& tangent) {
  // ε_ikm is non-zero only for i ≠ k, with m the third index and sign +1 for cyclic (i, k, m).
  auto third = [](int a, int b) { return 3 - a - b; };
  auto sign = [](int a, int b) { return (b - a + 3) % 3 == 1 ? 1.0 : -1.0; };
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      if (i == k) continue;
      for (int J = 0; J < 3; ++J)
        for (int L = 0; L < 3; ++L) {
          if (J == L) continue;
          tangent(3 * i + J, 3 * k + L) +=
              scale * sign(i, k) * sign(J, L) * F(third(i, k), third(J, L));
        }
    }
}

namespace neo_hookean {
namespace {

// U(J) = λ/2 ln²J − μ ln J and its first two derivatives at J0 = kMinVolumeRatio.
struct VolumetricTaylor {
  double u0, du0, ddu0;
};

VolumetricTaylor taylor_at_min(double mu, double lambda) {
  const double j0 = kMinVolumeRatio, log_j0 = std::log(j0);
  return {0.5 * lambda * log_j0 * log_j0 - mu * log_j0, (lambda * log_j0 - mu) / j0,
          (lambda * (1.0 - log_j0) + mu) / (j0 * j0)};
}

double volumetric_energy(double J, double mu, double lambda) {
  if (J >= kMinVolumeRatio) {
    const double log_j = std::log(J);
    return 0.5 * lambda * log_j * log_j - mu * log_j;
  }
  const auto t = taylor_at_min(mu, lambda);
  const double d = J - kMinVolumeRatio;
  return t.u0 + t.du0 * d + 0.5 * t.ddu0 * d * d;
}

// dU/dJ.
double volumetric_pressure_term(double J, double mu, double lambda) {
  if (J >= kMinVolumeRatio) return (lambda * std::log(J) - mu) / J;
  const auto t = taylor_at_min(mu, lambda);
  return t.du0 + t.ddu0 * (J - kMinVolumeRatio);
}

// d²U/dJ².
double volumetric_stiffness(double J, double mu, double lambda) {
  if (J >= kMinVolumeRatio) return (lambda * (1.0 - std::log(J)) + mu) / (J * J);
  return taylor_at_min(mu, lambda).ddu0;
}

}  // namespace

Eigen::Matrix<double, 9, 9> stress_tangent(const Eigen::Matrix3d& F, double mu, double lambda) {
  const Eigen::Matrix3d cof = cofactor(F);
  const double J = F.col(0).dot(cof.col(0));
  Eigen::Matrix<double, 9, 9> tangent = mu * Eigen::Matrix<double, 9, 9>::Identity();
  Eigen::Matrix<double, 9, 1> c;
  for (int k = 0; k < 9; ++k) c[k] = cof(k / 3, k % 3);
  tangent += volumetric_stiffness(J, mu, lambda) * c * c.transpose();
  add_cofactor_derivative(F, volumetric_pressure_term(J, mu, lambda), tangent);
  return tangent;
}

double lambda_energy_density(double J, double lambda) {
  const double j0 = kMinVolumeRatio, log_j0 = std::log(j0);
  if (J >= j0) return 0.5 * lambda * std::log(J) * std::log(J);
  const double d = J - j0;
  return 0.5 * lambda * log_j0 * log_j0 + lambda * log_j0 / j0 * d +
         0.5 * lambda * (1.0 - log_j0) / (j0 * j0) * d * d;
}

double lambda_pressure(double J, double lambda) {
  if (J >= kMinVolumeRatio) return lambda * std::log(J) / J;
  const double j0 = kMinVolumeRatio, log_j0 = std::log(j0);
  return lambda * log_j0 / j0 + lambda * (1.0 - log_j0) / (j0 * j0) * (J - j0);
}

Eigen::Matrix3d first_piola_stress_given_lambda_pressure(const Eigen::Matrix3d& F, double mu,
                                                         double lambda, double lambda_pressure_pa) {
  const Eigen::Matrix3d cof = cofactor(F);
  const double J = F.col(0).dot(cof.col(0));
  const double pressure_term =
      volumetric_pressure_term(J, mu, lambda) - lambda_pressure(J, lambda) + lambda_pressure_pa;
  return mu * F + pressure_term * cof;
}

double volumetric_stiffening(double J, double mu, double lambda) {
  return volumetric_stiffness(J, mu, lambda) / (lambda + mu);
}

double split_volumetric_stiffening(double nodal_J, double element_J, double mu, double lambda) {
  // U'' = λ(1 − ln J)/J² + μ/J² above kMinVolumeRatio; below it each part's quadratic continuation
  // keeps its curvature at kMinVolumeRatio.
  const double j_lambda = std::max(nodal_J, kMinVolumeRatio);
  const double j_mu = std::max(element_J, kMinVolumeRatio);
  const double lambda_part = lambda * (1.0 - std::log(j_lambda)) / (j_lambda * j_lambda);
  const double mu_part = mu / (j_mu * j_mu);
  return (lambda_part + mu_part) / (lambda + mu);
}

double energy_density(const Eigen::Matrix3d& F, double mu, double lambda) {
  return 0.5 * mu * (F.squaredNorm() - 3.0) + volumetric_energy(F.determinant(), mu, lambda);
}

Eigen::Matrix3d first_piola_stress(const Eigen::Matrix3d& F, double mu, double lambda) {
  // P = μF + U'(J) cof(F); at J = 1, U'(1) = −μ and cof(I) = I, so P(I) = 0.
  const Eigen::Matrix3d cof = cofactor(F);
  const double J = F.col(0).dot(cof.col(0));
  return mu * F + volumetric_pressure_term(J, mu, lambda) * cof;
}

}  // namespace neo_hookean

namespace mooney_rivlin {
namespace {

// g(J) = −4 c2 ln J and its first two derivatives, continued quadratically below J0.
struct LogTerm {
  double value, slope, curvature;
};

LogTerm log_term(double J, double c2) {
  const double j0 = neo_hookean::kMinVolumeRatio;
  if (J >= j0) return {-4.0 * c2 * std::log(J), -4.0 * c2 / J, 4.0 * c2 / (J * J)};
  const double d = J - j0;
  const double value = -4.0 * c2 * std::log(j0), slope = -4.0 * c2 / j0;
  const double curvature = 4.0 * c2 / (j0 * j0);
  return {value + slope * d + 0.5 * curvature * d * d, slope + curvature * d, curvature};
}

}  // namespace

double extra_energy_density(const Eigen::Matrix3d& F, double c2) {
  const Eigen::Matrix3d C = F.transpose() * F;
  const double i1 = C.trace(), i2 = 0.5 * (i1 * i1 - (C * C).trace());
  return c2 * (i2 - 3.0) + log_term(F.determinant(), c2).value;
}

Eigen::Matrix3d extra_first_piola_stress(const Eigen::Matrix3d& F, double c2) {
  // ∂I2/∂F = 2 (I1 F − F C); ∂(ln J)/∂F = cof F / J, with the continued slope for J < J0.
  const Eigen::Matrix3d C = F.transpose() * F;
  const Eigen::Matrix3d cof = cofactor(F);
  const double J = F.col(0).dot(cof.col(0));
  return 2.0 * c2 * (C.trace() * F - F * C) + log_term(J, c2).slope * cof;
}

Eigen::Matrix<double, 9, 9> extra_stress_tangent(const Eigen::Matrix3d& F, double c2) {
  // ∂[I1 F − F Fᵀ F]_iJ/∂F_kL = 2 F_kL F_iJ + I1 δik δJL − δik C_LJ − F_iL F_kJ − B_ik δJL.
  const Eigen::Matrix3d C = F.transpose() * F, B = F * F.transpose();
  const double i1 = C.trace();
  Eigen::Matrix<double, 9, 9> tangent;
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J)
      for (int k = 0; k < 3; ++k)
        for (int L = 0; L < 3; ++L) {
          const double dik = i == k, dJL = J == L;
          tangent(3 * i + J, 3 * k + L) = 2.0 * c2 *
                                          (2.0 * F(k, L) * F(i, J) + i1 * dik * dJL -
                                           dik * C(L, J) - F(i, L) * F(k, J) - B(i, k) * dJL);
        }
  const Eigen::Matrix3d cof = cofactor(F);
  const LogTerm g = log_term(F.col(0).dot(cof.col(0)), c2);
  Eigen::Matrix<double, 9, 1> c;
  for (int k = 0; k < 9; ++k) c[k] = cof(k / 3, k % 3);
  tangent += g.curvature * c * c.transpose();
  add_cofactor_derivative(F, g.slope, tangent);
  return tangent;
}

}  // namespace mooney_rivlin
}  // namespace liversim
