#include "liversim/sessions/grading.h"

namespace liversim {

RubricResult grade_against_rubric(std::span<const RubricCriterion> rubric,
                                  std::span<const MetricValue> metrics) {
  RubricResult result;
  double total = 0.0, passed = 0.0;
  result.all_passed = !rubric.empty();
  for (const RubricCriterion& criterion : rubric) {
    CriterionResult r{criterion, std::nullopt, false};
    for (const MetricValue& metric : metrics)
      if (metric.name == criterion.metric) r.value = metric.value;
    if (r.value)
      r.passed = criterion.rule == PassRule::at_most ? *r.value <= criterion.threshold
                                                     : *r.value >= criterion.threshold;
    total += criterion.weight;
    if (r.passed) passed += criterion.weight;
    result.all_passed = result.all_passed && r.passed;
    result.criteria.push_back(r);
  }
  if (total > 0.0) result.score_percent = 100.0 * passed / total;
  return result;
}

}  // namespace liversim
