#include "liversim/engine/parameter_ranges.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace liversim {
namespace {

namespace p = parameter;

// The limits and their reasons. Literature values are of quasi-static (surgical) loading; where
// the seed and the literature give nothing (viscoplastic law, fibres) the range is an assumption,
// and says so.
constexpr std::array kRanges{
    ParameterRange{p::youngs_modulus, "Young's modulus E", "Pa", 1000.0, 20000.0, true,
                   "quasi-static liver: 1-10 kPa by indentation and compression (the seed's "
                   "3.5 kPa), fibrotic tissue up to ~20 kPa; stiffer inclusions are lesions"},
    ParameterRange{p::poisson_ratio, "Poisson's ratio ν", "", 0.3, 0.499, false,
                   "perfused parenchyma is nearly incompressible (0.45-0.499 in FE liver models), "
                   "0.3 allows drained ex vivo tissue; the validator needs ν < 0.5"},
    ParameterRange{p::density, "density ρ", "kg/m³", 1000.0, 1100.0, false,
                   "liver 1050-1070 kg/m³ (the seed's 1060); the margin covers steatosis and "
                   "lesions"},
    ParameterRange{p::mooney_rivlin_fraction, "Mooney-Rivlin fraction c2/(c1 + c2)", "", 0.0, 0.5,
                   false,
                   "0 is Neo-Hookean (the default); Mooney-Rivlin fits of liver put c01 between 0 "
                   "and c10; < 0.75 keeps the volumetric λ positive at ν = 0.3 (validator)"},
    ParameterRange{p::e1, "Maxwell-arm modulus E1", "Pa", 500.0, 10000.0, true,
                   "the relaxing share of the instantaneous 1-20 kPa (liver relaxes to 30-70 % of "
                   "its peak stress); with E2 in range, E1 + E2 = E lies in E's range"},
    ParameterRange{p::e2, "relaxed modulus E2", "Pa", 500.0, 10000.0, true,
                   "the long-term share of the instantaneous 1-20 kPa; > 0, or creep is unbounded "
                   "(validator); with E1 in range, E1 + E2 = E lies in E's range"},
    ParameterRange{p::eta1, "Maxwell-arm viscosity η1", "Pa·s", 100.0, 100000.0, true,
                   "relaxation time τ = η1/E1 from 0.01 s to 200 s over E1's range, spanning the "
                   "fraction-of-a-second to minutes time constants of liver relaxation tests"},
    ParameterRange{p::yield_limit, "yield limit σs", "Pa", 10.0, 2000.0, true,
                   "assumed (the seed gives no value): the von Mises stress of 1-20 % strain at "
                   "1-20 kPa, so that tool loads go both below and above it"},
    ParameterRange{p::eta2, "viscoplastic viscosity η2", "Pa·sⁿ", 1000.0, 1e6, true,
                   "assumed (the seed gives no value): 1 kPa above yield creeps (σ − σs)·tⁿ/η2 = "
                   "100 % to 0.1 % in the first second, from paste-like to barely creeping"},
    ParameterRange{p::creep_index, "creep index n", "", 0.1, 1.0, false,
                   "primary (n < 1) to steady (n = 1) creep; n > 1 is tertiary creep (rupture, "
                   "rejected by the validator); tⁿ with n → 0 is a jump at yield"},
    ParameterRange{p::fibre_k1, "fibre stiffness k1", "Pa", 100.0, 10000.0, true,
                   "assumed (no liver HGO fit found): collagen of Glisson's capsule and vessel "
                   "walls, of the order of the matrix (HGO arterial fits: 0.56-2.4 kPa)"},
    ParameterRange{p::fibre_k2, "fibre stiffening k2", "", 0.1, 20.0, true,
                   "assumed: arterial HGO fits 0.7-0.84, collagen-rich tissue up to ~20; at 20 a "
                   "20 % stretch already stiffens the fibre ~50× (larger k2: case 6's guard)"},
    ParameterRange{p::mass_damping, "mass damping α", "1/s", 0.5, 50.0, true,
                   "a scene setting (default 8/s): below 0.5/s the liver rings for seconds, above "
                   "50/s (decay in 20 ms) it moves like honey"},
    ParameterRange{p::lesion_stiffness_ratio, "lesion stiffness / parenchyma", "", 1.0, 100.0, true,
                   "tumours are 1.5-10× the parenchyma by elastography; 100× (calcified lesions) "
                   "is the stiffest the suite tests (case 5)"},
    ParameterRange{p::fracture_toughness, "fracture toughness J", "J/m²", 20.0, 5000.0, true,
                   "liver 76-225 J/m² (porcine, by scalpel and needle; bovine 164); none is "
                   "published for liver tumours or cirrhosis: up to fibrous tissue (muscle "
                   "550-8000), down to a tenth of liver",
                   false},
    ParameterRange{p::blade_friction, "blade friction", "N/m", 0.0, 2000.0, false,
                   "assumed, none is published for a scalpel in liver: a third of the toughness "
                   "(friction 21 % and tearing 61 % of a needle's insertion force in porcine "
                   "tissue, Barnett, Lee & Moore 2015), 70 N/m for liver's 200 J/m²; 0 is a "
                   "frictionless blade",
                   false},
};

}  // namespace

double ParameterRange::at_fraction(double fraction) const {
  const double f = std::clamp(fraction, 0.0, 1.0);
  if (f == 1.0) return max;  // exactly, not max·(1 ± round-off)
  if (log_scale) return min * std::pow(max / min, f);
  return min + f * (max - min);
}

std::span<const ParameterRange> tissue_parameter_ranges() {
  return kRanges;
}

const ParameterRange* find_parameter_range(std::string_view name) {
  for (const ParameterRange& range : kRanges)
    if (range.name == name) return &range;
  return nullptr;
}

const ParameterRange& parameter_range(std::string_view name) {
  if (const ParameterRange* range = find_parameter_range(name)) return *range;
  throw std::out_of_range("no parameter range named \"" + std::string(name) + "\"");
}

}  // namespace liversim
