#pragma once
// Holzapfel–Gasser–Ogden collagen fibres (seed §3.3, with its two errors corrected, see
// docs/tissue-model.md): for each family with unit reference direction a,
//   I4 = a·C·a = |F a|²   (the seed's Eq. 5 carries a spurious 1/2)
//   Ψ_f = k1/(2 k2) (exp(k2 (I4 − 1)²) − 1)   (the seed's Eq. 6 writes k1/k2)
// in tension only (I4 > 1). The unconstrained form (I4, not the isochoric Ī4) is used, as FEBio's
// FEHolzapfelUnconstrained does, because the split form responds unphysically to volume change.

#include <Eigen/Core>

#include <optional>
#include <string>

namespace liversim {

struct FibreParameters {
  double k1_pa = 0.0;  // initial fibre stiffness
  double k2 = 0.0;     // dimensionless stiffening exponent (k2 → 0 is a linear fibre)
};

std::optional<std::string> validate(const FibreParameters& fibres);

namespace hgo {

// Past this exponent the exponential is continued linearly (C¹), so the energy, the stress and the
// stiffness stay finite at any stretch. exp(50) ≈ 5e21: far beyond any tissue, far from overflow.
inline constexpr double kMaxExponent = 50.0;

// Strain energy density of one family in J/m³ (0 in compression).
double energy_density(const Eigen::Matrix3d& F, const Eigen::Vector3d& a, const FibreParameters& p);

// First Piola–Kirchhoff stress of one family, P = 2 ψ4 (F a) ⊗ a with ψ4 = ∂Ψ_f/∂I4.
Eigen::Matrix3d first_piola_stress(const Eigen::Matrix3d& F, const Eigen::Vector3d& a,
                                   const FibreParameters& p);

// ∂P/∂F of one family as a 9×9 matrix (row 3i+J, column 3k+L):
// 2ψ4 δik a_J a_L + 4ψ44 (Fa)_i a_J (Fa)_k a_L in tension, zero otherwise.
Eigen::Matrix<double, 9, 9> stress_tangent(const Eigen::Matrix3d& F, const Eigen::Vector3d& a,
                                           const FibreParameters& p);

// An upper bound of the fibre's tangent stiffness ∂²Ψ_f/∂(Fa)² in Pa at this stretch, for the
// stable-step estimate: 2ψ4 + 4 I4 ψ44.
double tangent_modulus_pa(const Eigen::Matrix3d& F, const Eigen::Vector3d& a,
                          const FibreParameters& p);

}  // namespace hgo
}  // namespace liversim
