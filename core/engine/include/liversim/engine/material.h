#pragma once
// Tissue material parameters and the compressible Neo-Hookean stress used by the engine.

#include <Eigen/Core>

#include <optional>
#include <string>

namespace liversim {

// Isotropic elastic tissue. Defaults are the seed paper's liver (§4.2): E = 3500 Pa, ν = 0.49,
// ρ = 1060 kg/m³. Here E is the small-strain Young's modulus of the elastic base.
struct TissueMaterial {
  double youngs_modulus_pa = 3500.0;
  double poisson_ratio = 0.49;
  double density_kg_per_m3 = 1060.0;
  // Mooney–Rivlin option: the share f = c2/(c1 + c2) of the shear modulus carried by the I2 term
  // (0: Neo-Hookean). The small-strain moduli stay those of E and ν: μ = 2(c1 + c2), and the
  // volumetric λ is reduced by the 4 c2 the I2 term contributes.
  double mooney_rivlin_fraction = 0.0;

  double shear_modulus_pa() const { return youngs_modulus_pa / (2.0 * (1.0 + poisson_ratio)); }
  double lame_lambda_pa() const {
    return youngs_modulus_pa * poisson_ratio /
           ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
  }
};

// Returns a message naming the first parameter that is outside its physical range (or not a
// number), or nothing when all are valid.
std::optional<std::string> validate(const TissueMaterial& material);

// Compressible Neo-Hookean (Bonet & Wood):
//   Ψ(F) = μ/2 (tr FᵀF − 3) − μ ln J + λ/2 (ln J)².
// Below J = kMinVolumeRatio the volumetric part U(J) = λ/2 ln²J − μ ln J is continued by its
// second-order Taylor polynomial, so Ψ and P stay finite for J ≤ 0 (inverted elements) and the
// restoring pressure pushes an inverted element back out.
namespace neo_hookean {

inline constexpr double kMinVolumeRatio = 0.2;

// Strain energy density Ψ in J/m³.
double energy_density(const Eigen::Matrix3d& F, double mu, double lambda);

// First Piola–Kirchhoff stress P = ∂Ψ/∂F in Pa.
Eigen::Matrix3d first_piola_stress(const Eigen::Matrix3d& F, double mu, double lambda);

// The same stress with the λ part of the pressure, p_λ(J) = λ ln J / J, replaced by a given one:
// P = μF + (U'(J) − p_λ(J) + lambda_pressure_pa) cof F. Average nodal pressure passes the mean of
// the element's corners' nodal p_λ, which makes its forces the gradient of its nodal energy.
Eigen::Matrix3d first_piola_stress_given_lambda_pressure(const Eigen::Matrix3d& F, double mu,
                                                         double lambda, double lambda_pressure_pa);

// W_λ(J) = λ/2·ln²J, the λ part of U(J) (its derivative is p_λ), continued below kMinVolumeRatio
// as p_λ is. Σ over nodes of V·W_λ(J_avg) is the volumetric energy of average nodal pressure.
double lambda_energy_density(double J, double lambda);
// p_λ(J) = dW_λ/dJ = λ ln J / J, continued linearly below kMinVolumeRatio. Linear in λ, as W_λ is.
double lambda_pressure(double J, double lambda);

// ∂P/∂F as a 9×9 matrix over row-major flattened indices (row 3i+J for P_iJ, column 3k+L for
// F_kL): μ δik δJL + U''(J) cof_iJ cof_kL + U'(J) ∂cof_iJ/∂F_kL. Needed by implicit integrators.
Eigen::Matrix<double, 9, 9> stress_tangent(const Eigen::Matrix3d& F, double mu, double lambda);

// U''(J) / U''(1): how much stiffer the volumetric response is at J than at rest (≥ 1 under
// compression). The stable explicit step scales with its inverse square root.
double volumetric_stiffening(double J, double mu, double lambda);
// The same with the λ pressure averaged over nodes: the λ part at the nodal J, the −μ/J part at
// the element's (1 at rest; the unsplit value when both are the same).
double split_volumetric_stiffening(double nodal_J, double element_J, double mu, double lambda);

}  // namespace neo_hookean

// The I2 part of compressible Mooney–Rivlin, Ψ = c1 (I1 − 3) + c2 (I2 − 3) − (2c1 + 4c2) ln J
// + λ/2 ln²J: the Neo-Hookean functions above with μ = 2c1 give all but c2 (I2 − 3) − 4c2 ln J,
// which these add (the ln J term Taylor-continued below kMinVolumeRatio, as for Neo-Hookean).
namespace mooney_rivlin {
double extra_energy_density(const Eigen::Matrix3d& F, double c2);
Eigen::Matrix3d extra_first_piola_stress(const Eigen::Matrix3d& F, double c2);
Eigen::Matrix<double, 9, 9> extra_stress_tangent(const Eigen::Matrix3d& F, double c2);
}  // namespace mooney_rivlin

// Cofactor matrix cof(F) = J F⁻ᵀ = ∂J/∂F, computed without inverting F (defined for J ≤ 0).
Eigen::Matrix3d cofactor(const Eigen::Matrix3d& F);

// ∂cof(F)_iJ/∂F_kL = ε_ikm ε_JLM F_mM, scaled by `scale` and added to a 9×9 tangent.
void add_cofactor_derivative(const Eigen::Matrix3d& F, double scale,
                             Eigen::Matrix<double, 9, 9>& tangent);

}  // namespace liversim
