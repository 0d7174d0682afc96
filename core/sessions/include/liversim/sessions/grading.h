#pragma once
// A session graded against its scenario's rubric (scenario.h): each criterion passes when its
// metric was measured and meets the threshold; the score is the passed criteria's share of the
// total weight. Defined in docs/session-metrics.md.

#include "liversim/scenario/scenario.h"
#include "liversim/sessions/session_store.h"

#include <optional>
#include <span>
#include <vector>

namespace liversim {

struct CriterionResult {
  RubricCriterion criterion;
  std::optional<double> value;  // none: the session has no such metric (it fails)
  bool passed = false;
};

struct RubricResult {
  std::vector<CriterionResult> criteria;  // in the rubric's order
  // 100 · Σ weight of the passed / Σ weight; none for a rubric without weight (or none at all).
  std::optional<double> score_percent;
  bool all_passed = false;  // every criterion passed (false for an empty rubric)
};

RubricResult grade_against_rubric(std::span<const RubricCriterion> rubric,
                                  std::span<const MetricValue> metrics);

}  // namespace liversim
