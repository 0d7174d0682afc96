// Grading a session against its scenario's rubric (issue 10): pass rules, weights, missing
// metrics, and the score, against answers worked out by hand.
#include "liversim/sessions/grading.h"

#include <gtest/gtest.h>

namespace liversim {
namespace {

TEST(Grading, TheScoreIsThePassedCriteriasShareOfTheWeight) {
  const std::vector<RubricCriterion> rubric{
      {"task_success", 3.0, PassRule::at_least, 1.0},
      {"peak_force_n", 1.0, PassRule::at_most, 2.0},
      {"time_above_safe_force_s", 1.0, PassRule::at_most, 5.0},
      {"lesion_margin_mm", 5.0, PassRule::at_least, 10.0},
  };
  // Success, 2.0 N exactly (at most: passes), 5.5 s above the safe force (fails), no margin
  // (nothing was cut: fails). Passed weight 3 + 1 of 10.
  const std::vector<MetricValue> metrics{{"peak_force_n", 2.0},
                                         {"task_success", 1.0},
                                         {"time_above_safe_force_s", 5.5},
                                         {"path_length_mm", 123.0}};
  const RubricResult result = grade_against_rubric(rubric, metrics);
  ASSERT_EQ(result.criteria.size(), 4u);
  EXPECT_TRUE(result.criteria[0].passed);
  EXPECT_TRUE(result.criteria[1].passed);
  EXPECT_FALSE(result.criteria[2].passed);
  EXPECT_EQ(result.criteria[2].value, std::optional<double>(5.5));
  EXPECT_FALSE(result.criteria[3].passed);
  EXPECT_FALSE(result.criteria[3].value);
  EXPECT_EQ(result.score_percent, std::optional<double>(40.0));
  EXPECT_FALSE(result.all_passed);

  const std::vector<MetricValue> good{{"peak_force_n", 1.0},
                                      {"task_success", 1.0},
                                      {"time_above_safe_force_s", 0.0},
                                      {"lesion_margin_mm", 10.0}};
  const RubricResult best = grade_against_rubric(rubric, good);
  EXPECT_EQ(best.score_percent, std::optional<double>(100.0));
  EXPECT_TRUE(best.all_passed);
}

TEST(Grading, ARubricWithoutWeightHasNoScore) {
  EXPECT_FALSE(grade_against_rubric({}, {}).score_percent);
  EXPECT_FALSE(grade_against_rubric({}, {}).all_passed);
  const std::vector<RubricCriterion> unweighted{{"peak_force_n", 0.0, PassRule::at_most, 2.0}};
  const RubricResult result =
      grade_against_rubric(unweighted, std::vector<MetricValue>{{"peak_force_n", 1.0}});
  EXPECT_FALSE(result.score_percent);
  EXPECT_TRUE(result.all_passed);
}

}  // namespace
}  // namespace liversim
