// The accuracy study runs its grid, measures errors against its reference and costs, and refuses
// options it cannot honour with a message naming them.
#include "liversim/studies/accuracy_study.h"

#include <gtest/gtest.h>

#include <cmath>

namespace liversim {
namespace {

AccuracyStudyOptions small_study() {
  AccuracyStudyOptions options;
  options.tet_counts = {3841};
  options.integrators = {IntegratorKind::central_difference, IntegratorKind::rk4,
                         IntegratorKind::backward_euler};
  options.steps_s = {5e-4, 2.5e-4};
  options.tolerances_m = {};
  options.duration_s = 0.002;
  options.reference_refinement = 16;
  return options;
}

TEST(AccuracyStudy, MeasuresEveryRunOfTheGrid) {
  const AccuracyStudyOptions options = small_study();
  int calls = 0, last_done = -1, total = 0;
  const AccuracyStudyResult result =
      run_accuracy_study(options, [&](const StudyProgressReport& report) {
        EXPECT_GE(report.runs_done, last_done);
        EXPECT_GE(report.fraction_of_run, 0.0);
        EXPECT_LE(report.fraction_of_run, 1.0);
        last_done = report.runs_done;
        total = report.runs_total;
        ++calls;
        return true;
      });
  ASSERT_EQ(result.rows.size(), 6u);  // 3 integrators × 2 steps
  EXPECT_EQ(total, 7);                // and the reference
  EXPECT_EQ(last_done, total);
  ASSERT_EQ(result.mesh_rows.size(), 1u);
  EXPECT_EQ(result.mesh_rows[0].difference_from_finest_m, 0.0);  // it is the finest
  EXPECT_GT(result.mesh_rows[0].displacement_m.norm(), 0.0);
  for (const AccuracyStudyRow& row : result.rows) {
    EXPECT_TRUE(std::isfinite(row.max_node_error_m)) << integrator_name(row.integrator);
    EXPECT_GE(row.max_node_error_m, row.marked_point_error_m);
    EXPECT_GT(row.wall_s, 0.0);
    EXPECT_GT(row.steps.force_evaluations, 0);
    EXPECT_GT(row.displacement_m, 0.0);
  }
  // A finer step of the same scheme is more accurate, and RK4 beats central difference at the
  // same step (order 4 against 2, both within their stability interval at 0.25 ms).
  auto row_of = [&](IntegratorKind kind, double step) {
    for (const AccuracyStudyRow& row : result.rows)
      if (row.integrator == kind && row.step_s == step) return row;
    ADD_FAILURE() << "missing run";
    return AccuracyStudyRow{};
  };
  for (IntegratorKind kind : options.integrators)
    EXPECT_LT(row_of(kind, 2.5e-4).max_node_error_m, row_of(kind, 5e-4).max_node_error_m)
        << integrator_name(kind);
  EXPECT_LT(row_of(IntegratorKind::rk4, 2.5e-4).max_node_error_m,
            row_of(IntegratorKind::central_difference, 2.5e-4).max_node_error_m);
  EXPECT_GT(row_of(IntegratorKind::backward_euler, 2.5e-4).steps.linear_solves, 0);
}

// A cancel is honoured within the run under way, not only between runs: a reference of many
// small steps can take long.
TEST(AccuracyStudy, ACancelStopsTheRunUnderWayAtItsNextLoadInterval) {
  AccuracyStudyOptions options = small_study();
  int reports = 0;
  double last_fraction = -1.0;
  EXPECT_THROW(run_accuracy_study(options,
                                  [&](const StudyProgressReport& report) {
                                    ++reports;
                                    last_fraction = report.fraction_of_run;
                                    EXPECT_EQ(report.runs_done, 0);
                                    EXPECT_NE(report.running.find("reference"), std::string::npos);
                                    return report.fraction_of_run == 0.0;  // cancel mid-run
                                  }),
               StudyCancelled);
  // The start of the reference, then the end of its first load interval (of 4: 2 ms at 0.5 ms).
  EXPECT_EQ(reports, 2);
  EXPECT_DOUBLE_EQ(last_fraction, 0.25);
}

TEST(AccuracyStudy, TheBestTradeOffsAreTheRunsNoOtherBeatsInErrorAndCost) {
  AccuracyStudyRow cheap_rough, dear_fine, dominated, tie;
  cheap_rough.max_node_error_m = 1e-4, cheap_rough.wall_s = 1.0;
  dear_fine.max_node_error_m = 1e-7, dear_fine.wall_s = 9.0;
  dominated.max_node_error_m = 2e-4, dominated.wall_s = 3.0;  // rougher and dearer than the first
  tie = cheap_rough;                                          // equal runs do not beat each other
  const std::vector<bool> front = pareto_front({&cheap_rough, &dear_fine, &dominated, &tie});
  EXPECT_EQ(front, (std::vector<bool>{true, true, false, true}));
}

TEST(AccuracyStudy, ObservedOrderIsUndefinedForAStabilityLimitedRun) {
  AccuracyStudyRow coarse, fine;
  coarse.step_s = 2e-3;
  fine.step_s = 1e-3;
  coarse.max_node_error_m = 4e-6;
  fine.max_node_error_m = 1e-6;
  EXPECT_NEAR(observed_order(coarse, fine), 2.0, 1e-12);
  coarse.steps.stability_limited_steps = 3;
  EXPECT_TRUE(std::isnan(observed_order(coarse, fine)));
}

TEST(AccuracyStudy, RefusesOptionsItCannotHonour) {
  auto message_of = [](const AccuracyStudyOptions& options) {
    try {
      run_accuracy_study(options);
    } catch (const std::invalid_argument& error) {
      return std::string(error.what());
    }
    return std::string("(accepted)");
  };
  AccuracyStudyOptions options = small_study();
  options.steps_s = {1e-3, 3e-4};
  EXPECT_NE(message_of(options).find("does not divide"), std::string::npos) << message_of(options);
  options = small_study();
  options.steps_s = {-1e-3};
  EXPECT_NE(message_of(options).find("step -0.001 s is invalid"), std::string::npos);
  options = small_study();
  options.tet_counts.clear();
  EXPECT_NE(message_of(options).find("mesh size"), std::string::npos);
  options = small_study();
  options.integrators = {IntegratorKind::dopri5};
  options.tolerances_m = {std::nan("")};
  EXPECT_NE(message_of(options).find("tolerance"), std::string::npos);
  options = small_study();
  options.duration_s = 0.0021;
  EXPECT_NE(message_of(options).find("whole number"), std::string::npos);
  EXPECT_EQ(study_effects_from_name(study_effects_name(StudyEffects::fibres)),
            StudyEffects::fibres);
  EXPECT_FALSE(study_effects_from_name("plastic"));
}

}  // namespace
}  // namespace liversim
