// The stability suite (issue 5): every named hard case of core's suite (stability_suite.h) must
// pass each of its checks: no NaN or infinity, no give-up, energy books within their tolerance,
// displacement bounded, and the case's own answers.
#include "liversim/studies/stability_suite.h"

#include <gtest/gtest.h>

#include <string>

namespace liversim {
namespace {

class StabilityCaseTest : public ::testing::TestWithParam<std::string> {};

TEST_P(StabilityCaseTest, EveryRunPassesEveryCheck) {
  const StabilityCase* stability_case = find_stability_case(GetParam());
  ASSERT_NE(stability_case, nullptr);
  StabilitySuiteOptions options;
  options.shared_data_dir = std::filesystem::path(LIVERSIM_SHARED_DIR) / "data";
  const std::vector<StabilityRun> runs = run_stability_case(*stability_case, options);
  ASSERT_FALSE(runs.empty());
  for (const StabilityRun& run : runs) {
    EXPECT_TRUE(run.error.empty()) << run.variant << ": " << run.error;
    EXPECT_GT(run.intervals, 0) << run.variant;
    EXPECT_FALSE(run.gave_up) << run.variant << " gave up at t = " << run.gave_up_at_s
                              << " s: " << run.last_problem;
    for (const StabilityCheck& check : run.checks)
      EXPECT_TRUE(check.passed()) << run.variant << ": " << check.what << " = " << check.value
                                  << ", limit " << (check.at_most ? "≤ " : "≥ ") << check.limit;
  }
}

std::vector<std::string> case_names() {
  std::vector<std::string> names;
  for (const StabilityCase& c : stability_cases()) names.emplace_back(c.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(Suite, StabilityCaseTest, ::testing::ValuesIn(case_names()),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name;
                         });

TEST(StabilitySuite, CasesAreNumberedAndNamedOnce) {
  int previous = 0;
  for (const StabilityCase& c : stability_cases()) {
    EXPECT_GT(c.number, previous) << c.name;
    previous = c.number;
    EXPECT_EQ(find_stability_case(c.name), &c);
  }
  EXPECT_EQ(find_stability_case("no-such-case"), nullptr);
}

}  // namespace
}  // namespace liversim
