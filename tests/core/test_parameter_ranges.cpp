// The documented parameter ranges (core/parameter_ranges.h): well formed, and every corner of
// them accepted by the validators, so a scenario inside them always builds.
#include "liversim/engine/parameter_ranges.h"

#include "liversim/engine/fibres.h"
#include "liversim/engine/material.h"
#include "liversim/engine/viscous_tissue.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace liversim {
namespace {

TEST(ParameterRanges, EveryRangeIsWellFormedAndFoundByItsKey) {
  ASSERT_FALSE(tissue_parameter_ranges().empty());
  for (const ParameterRange& range : tissue_parameter_ranges()) {
    EXPECT_TRUE(std::isfinite(range.min) && std::isfinite(range.max)) << range.name;
    EXPECT_LT(range.min, range.max) << range.name;
    if (range.log_scale) {
      EXPECT_GT(range.min, 0.0) << range.name;
    }
    EXPECT_FALSE(range.why.empty()) << range.name;
    EXPECT_DOUBLE_EQ(range.at_fraction(0.0), range.min) << range.name;
    EXPECT_DOUBLE_EQ(range.at_fraction(1.0), range.max) << range.name;
    const double middle = range.at_fraction(0.5);
    EXPECT_TRUE(range.contains(middle)) << range.name;
    // Log-uniform: the middle is the geometric mean; linear: the arithmetic mean.
    EXPECT_NEAR(middle,
                range.log_scale ? std::sqrt(range.min * range.max) : 0.5 * (range.min + range.max),
                1e-12 * range.max)
        << range.name;
    EXPECT_EQ(find_parameter_range(range.name), &range);
  }
  EXPECT_FALSE(parameter_range(parameter::poisson_ratio).contains(std::nan("")));
  EXPECT_EQ(find_parameter_range("stiffness"), nullptr);
  EXPECT_THROW(parameter_range("stiffness"), std::out_of_range);
}

// Every corner of the ranges passes the validators (each law on its own parameters).
TEST(ParameterRanges, TheirCornersPassTheValidators) {
  const ParameterRange& e = parameter_range(parameter::youngs_modulus);
  const ParameterRange& nu = parameter_range(parameter::poisson_ratio);
  const ParameterRange& rho = parameter_range(parameter::density);
  const ParameterRange& mr = parameter_range(parameter::mooney_rivlin_fraction);
  for (double f : {0.0, 1.0})
    for (double g : {0.0, 1.0})
      for (double h : {0.0, 1.0})
        for (double m : {0.0, 1.0}) {
          TissueMaterial material{e.at_fraction(f), nu.at_fraction(g), rho.at_fraction(h)};
          material.mooney_rivlin_fraction = mr.at_fraction(m);
          EXPECT_FALSE(validate(material)) << *validate(material);
        }
  const ParameterRange& k1 = parameter_range(parameter::fibre_k1);
  const ParameterRange& k2 = parameter_range(parameter::fibre_k2);
  for (double f : {0.0, 1.0})
    for (double g : {0.0, 1.0})
      EXPECT_FALSE(validate(FibreParameters{k1.at_fraction(f), k2.at_fraction(g)}));
  const ParameterRange& e1 = parameter_range(parameter::e1);
  const ParameterRange& e2 = parameter_range(parameter::e2);
  const ParameterRange& eta1 = parameter_range(parameter::eta1);
  const ParameterRange& yield = parameter_range(parameter::yield_limit);
  const ParameterRange& eta2 = parameter_range(parameter::eta2);
  const ParameterRange& n = parameter_range(parameter::creep_index);
  for (double f : {0.0, 1.0}) {
    const ViscousTissueParameters law{
        {e1.at_fraction(f), e2.at_fraction(1.0 - f), eta1.at_fraction(f)},
        nu.at_fraction(f),
        ViscoplasticParameters{yield.at_fraction(f), eta2.at_fraction(1.0 - f), n.at_fraction(f)}};
    EXPECT_FALSE(validate(law)) << *validate(law);
    // E = E1 + E2 stays within E's range at the corners of E1 and E2.
    EXPECT_TRUE(e.contains(e1.at_fraction(f) + e2.at_fraction(f))) << f;
  }
}

}  // namespace
}  // namespace liversim
