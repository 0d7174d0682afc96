#pragma once
// The stress an organ bears in vivo under its own weight, which its yield limit is measured from.
//
// The seed's yield limit (tens of Pa) describes overstress by an instrument; the liver's weight
// alone stresses it far past that (ρ·g·h ≈ 0.5–1 kPa), so with gravity on every element crept and
// the organ flattened for as long as the scene ran (issue 42). A liver in the abdomen does not
// flow under its weight: it has borne it all its life. So each element's yield limit is raised by
// the largest von Mises stress it bears as the organ settles under gravity on its support, as a
// tissue hardened to the load it has always carried (isotropic hardening up to its in-vivo
// stress). What an instrument adds above that yields as the seed describes. Documented in
// docs/tissue-model.md.

#include "liversim/engine/model.h"

#include <vector>

namespace liversim {

// How long the organ settles: on its bed (held and damped, support.h) the wedge resection's liver
// at 5406 tetrahedra has the same median, 90th percentile and largest in-vivo stress after 1 s and
// after 16 s of settling (one element of 5450 rises 50 Pa more); the Maxwell arm relaxes with
// τ = 1 s. What the stress changes after this is left to the yield limit's own margin.
inline constexpr double kInVivoSettlingTime_s = 2.0;

// Per element, the largest von Mises stress of the Kirchhoff stress (Pa) while `model`, started at
// rest with its viscoplasticity switched off, settles under its gravity on its support for
// `settling_time_s`, sampled every 2 ms (the law read at each sample); 0 in elements of regions that do not yield. Empty
// when the model has no gravity or no region that yields. Runs on the calling thread.
std::vector<double> in_vivo_stress_pa(const SimModel& model,
                                      double settling_time_s = kInVivoSettlingTime_s);

// What element e's yield limit is raised by: its in-vivo stress (Pa), 0 when the model has none.
inline double yield_raise_pa(const SimModel& model, std::size_t e) {
  return model.in_vivo_stress_pa.empty() ? 0.0 : model.in_vivo_stress_pa[e];
}

}  // namespace liversim
