#pragma once
// The documented physical range of every tissue and model parameter a scenario can set, in one
// place: for scenario validation, for the limits of the UI's spin boxes, for the seeded parameter
// sweep of the stability suite (case 12), and for the docs (each entry says why). Every range lies
// inside what the validators accept (material.h, fibres.h, viscous_tissue.h, model.h), so any value
// drawn from it builds a model; the ranges are narrower: they are what a liver (or a lesion in it)
// can plausibly be, not merely what the mathematics allows.
//
// Coupled parameters: with viscoelasticity the Young's modulus is not free but E = E1 + E2 (the
// instantaneous modulus, model.h); the E1 and E2 ranges are chosen so that their sum lies in E's
// range. A Mooney–Rivlin fraction below 0.5 is valid for every Poisson's ratio in range (the
// validator needs f < ν/(1 − 2ν), which is 0.75 at ν = 0.3); it applies to elastic regions only
// (build_model rejects it with viscoelasticity, whose elastic base is Neo-Hookean). A lesion's
// Young's modulus is the parenchyma's times the lesion stiffness ratio, so it may exceed E's range.

#include <span>
#include <string_view>

namespace liversim {

struct ParameterRange {
  std::string_view name;   // key, the name of the field it sets, e.g. "youngs_modulus_pa"
  std::string_view label;  // for people, e.g. "Young's modulus E"
  std::string_view unit;   // e.g. "Pa", "1/s"; "" for dimensionless
  double min = 0.0;        // inclusive
  double max = 0.0;        // inclusive
  // Spans decades: sample log-uniformly, step a spin box by factors. (min > 0 when set.)
  bool log_scale = false;
  std::string_view why;  // one line: where the limits come from
  // Drawn by the stability suite's parameter sweep (case 12); not a parameter of the forces
  // otherwise (the fracture toughness only holds the scalpel back).
  bool swept = true;

  bool contains(double value) const { return value >= min && value <= max; }  // NaN: false
  // The value at `fraction` (0: min, 1: max) of the range, linearly or log-uniformly: a uniform
  // fraction gives a sample with the range's distribution.
  double at_fraction(double fraction) const;
};

// Keys of the entries (ParameterRange::name).
namespace parameter {
inline constexpr std::string_view youngs_modulus = "youngs_modulus_pa";
inline constexpr std::string_view poisson_ratio = "poisson_ratio";
inline constexpr std::string_view density = "density_kg_per_m3";
inline constexpr std::string_view mooney_rivlin_fraction = "mooney_rivlin_fraction";
inline constexpr std::string_view e1 = "e1_pa";
inline constexpr std::string_view e2 = "e2_pa";
inline constexpr std::string_view eta1 = "eta1_pa_s";
inline constexpr std::string_view yield_limit = "yield_limit_pa";
inline constexpr std::string_view eta2 = "eta2_pa_s_pow_n";
inline constexpr std::string_view creep_index = "creep_index_n";
inline constexpr std::string_view fibre_k1 = "k1_pa";
inline constexpr std::string_view fibre_k2 = "k2";
inline constexpr std::string_view mass_damping = "mass_damping_per_s";
inline constexpr std::string_view lesion_stiffness_ratio = "lesion_stiffness_ratio";
inline constexpr std::string_view fracture_toughness = "fracture_toughness_j_per_m2";
inline constexpr std::string_view blade_friction = "blade_friction_n_per_m";
}  // namespace parameter

// Every range, in the order above.
std::span<const ParameterRange> tissue_parameter_ranges();

// The range of the parameter with this key, or nullptr.
const ParameterRange* find_parameter_range(std::string_view name);
// The same; throws std::out_of_range for an unknown key.
const ParameterRange& parameter_range(std::string_view name);

}  // namespace liversim
