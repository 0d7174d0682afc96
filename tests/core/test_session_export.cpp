// Sessions as CSV (issue 10): RFC 4180 quoting, and the metrics against the rubric.
#include "liversim/sessions/session_export.h"

#include <gtest/gtest.h>

#include <sstream>

namespace liversim {
namespace {

TEST(SessionExport, FieldsWithCommasQuotesOrLineBreaksAreQuotedWithQuotesDoubled) {
  EXPECT_EQ(csv_field("plain text"), "plain text");
  EXPECT_EQ(csv_field("a,b"), "\"a,b\"");
  EXPECT_EQ(csv_field("say \"stop\""), "\"say \"\"stop\"\"\"");
  EXPECT_EQ(csv_field("two\nlines"), "\"two\nlines\"");
  std::ostringstream out;
  write_events_csv(
      std::vector<SessionEvent>{{0.5, SessionEventKind::excessive_force, "1.6 N"},
                                {1.25, SessionEventKind::lesion_breach, "T1, \"left\""},
                                {1.5, SessionEventKind::grasp, "", Hand::left}},
      out);
  // Each event with its hand (issue 43).
  EXPECT_EQ(out.str(),
            "time_s,kind,detail,hand\n0.5,excessive_force,1.6 N,right\n1.25,lesion_breach,\"T1, "
            "\"\"left\"\"\",right\n1.5,grasp,,left\n");
}

TEST(SessionExport, MetricsCarryTheirUnitCriterionAndPassAndTheScoreComesLast) {
  const std::vector<RubricCriterion> rubric{{"peak_force_n", 1.0, PassRule::at_most, 2.0},
                                            {"lesion_margin_mm", 3.0, PassRule::at_least, 10.0}};
  const std::vector<MetricValue> metrics{{"path_length_mm", 12.5}, {"peak_force_n", 1.5}};
  std::ostringstream out;
  write_metrics_csv(metrics, grade_against_rubric(rubric, metrics), out);
  EXPECT_EQ(out.str(),
            "metric,value,unit,criterion,threshold,weight,passed\n"
            "path_length_mm,12.5,mm,,,,\n"
            "peak_force_n,1.5,N,at_most,2,1,1\n"
            "lesion_margin_mm,,,at_least,10,3,0\n"
            "score_percent,25,%,,,,\n");
}

}  // namespace
}  // namespace liversim
