// Trace metrics (docs/session-metrics.md) on synthetic servo traces whose answers follow by hand:
// the frames are samples of piecewise-linear position and force, so a straight line's length, a
// square wave's integrals and its crossing times are known in closed form.
#include "liversim/scenario/scenario.h"
#include "liversim/sessions/session_store.h"
#include "liversim/sessions/trace_metrics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

namespace liversim {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kFrameS = 1e-3;  // the servo's nominal 1 kHz

// Frame i sits at i·kFrameS rounded, so each Δt is good to ε·t_max, relatively n·ε for n = t_max /
// Δt intervals; sums of positive terms keep the worst term's relative error plus n·ε for the
// additions, and a ratio or square root of two such sums at most adds them: 8·n·ε bounds each.
double relative_tolerance(int intervals) {
  return 8.0 * intervals * kEps;
}

ServoFrame frame_at(double time_s, const Eigen::Vector3d& position_mm,
                    const Eigen::Vector3d& force_n = Eigen::Vector3d::Zero()) {
  ServoFrame frame;
  frame.time_s = time_s;
  frame.sample.position_mm = position_mm;
  frame.force_n = force_n;
  return frame;
}

const std::vector<ToolInterval> kProbeThroughout = {{-1.0, ToolKind::probe}};

TEST(TraceMetrics, StraightLineAtConstantSpeedHasItsExactLength) {
  const Eigen::Vector3d start_mm(10.0, -5.0, 30.0);
  const Eigen::Vector3d direction = Eigen::Vector3d(3.0, 4.0, 12.0) / 13.0;  // unit: 3-4-5, 5-12-13
  const double speed_mm_per_s = 20.0;
  const int intervals = 1000;
  std::vector<ServoFrame> frames;
  for (int i = 0; i <= intervals; ++i) {
    const double t_s = i * kFrameS;
    frames.push_back(frame_at(t_s, start_mm + speed_mm_per_s * t_s * direction));
  }
  // The scalpel's interval ends before the trace starts and the forceps' begins after it ends.
  const std::vector<ToolInterval> tools = {
      {-5.0, ToolKind::scalpel}, {-1.0, ToolKind::probe}, {2.0, ToolKind::forceps}};

  const TraceMetrics metrics = compute_trace_metrics(frames, tools, WorkspaceMapping{}, {});

  const double expected_mm = speed_mm_per_s * intervals * kFrameS;  // 20 mm in 1 s
  // Positions up to 50 mm are rounded to ε·50 mm, so each segment is good to about 2ε·50 mm.
  const double tolerance_mm = intervals * 2.0 * kEps * 50.0 + relative_tolerance(intervals) * 20.0;
  EXPECT_NEAR(metrics.path_length_mm, expected_mm, tolerance_mm);
  EXPECT_EQ(metrics.movements, 1);
  ASSERT_EQ(metrics.per_tool.size(), 1u);
  ASSERT_TRUE(metrics.per_tool.contains(ToolKind::probe));
  EXPECT_EQ(metrics.per_tool.at(ToolKind::probe).path_length_mm, metrics.path_length_mm);
  EXPECT_EQ(metrics.per_tool.at(ToolKind::probe).movements, 1);
  EXPECT_EQ(metrics.task_time_s, 0.0);  // no force: never in contact
}

// Three pulses of H = 2 N, each held for 100 frames (99 intervals) and reached in one interval
// from and back to 0 N: the linear ramps cross the thresholds at known fractions of a frame.
TEST(TraceMetrics, SquareWaveForceHasItsHandComputedFigures) {
  const double high_n = 2.0;
  const int intervals = 1000;
  const int pulse_starts[] = {100, 400, 700};
  std::vector<ServoFrame> frames;
  for (int i = 0; i <= intervals; ++i) {
    bool on = false;
    for (const int start : pulse_starts) on = on || (i >= start && i < start + 100);
    frames.push_back(frame_at(i * kFrameS, Eigen::Vector3d::Zero(),
                              Eigen::Vector3d(0.0, 0.0, on ? high_n : 0.0)));
  }
  const TraceMetricSettings settings;  // contact 0.02 N, safe 1.5 N
  const double c = settings.contact_force_n, s = settings.safe_force_n, h = high_n, dt = kFrameS;
  const double plateau_s = 99 * dt;

  const TraceMetrics metrics =
      compute_trace_metrics(frames, kProbeThroughout, WorkspaceMapping{}, settings);

  const double tolerance = relative_tolerance(intervals);
  EXPECT_EQ(metrics.peak_force_n, high_n);
  EXPECT_NEAR(metrics.peak_force_rate_n_per_s, h / dt, tolerance * h / dt);
  // Trapezoids: each pulse is a plateau plus two triangles of half a frame's height·Δt.
  const double integral_n_s = 3 * (h * plateau_s + h * dt);  // 0.6 N·s
  EXPECT_NEAR(metrics.force_integral_n_s, integral_n_s, tolerance * integral_n_s);
  // Above 1.5 N from 0.75 of the rising frame to 0.25 into the falling one (e.g. 0.09975 s to
  // 0.19925 s for the first pulse).
  const double above_safe_s = 3 * (plateau_s + 2 * dt * (h - s) / h);  // 0.2985 s
  EXPECT_NEAR(metrics.time_above_safe_force_s, above_safe_s, tolerance * above_safe_s);
  // In contact from c/h of the rising frame on: the ramp part in contact lasts Δt·(h − c)/h, and
  // there the force goes linearly from c to h.
  const double ramp_s = dt * (h - c) / h;
  const double contact_s = 3 * (plateau_s + 2 * ramp_s);
  const double contact_integral = 3 * (h * plateau_s + 2 * ramp_s * (c + h) / 2);
  const double contact_square_integral =
      3 * (h * h * plateau_s + 2 * ramp_s * (c * c + c * h + h * h) / 3);
  const double mean_n = contact_integral / contact_s;                   // 1.98059 N
  const double rms_n = std::sqrt(contact_square_integral / contact_s);  // 1.98698 N
  EXPECT_NEAR(metrics.mean_force_n, mean_n, tolerance * mean_n);
  EXPECT_NEAR(metrics.rms_force_n, rms_n, tolerance * rms_n);
  const double first_contact_s = 99 * dt + dt * c / h;  // 0.09901 s
  EXPECT_NEAR(metrics.task_time_s, 1.0 - first_contact_s, tolerance);
}

// Two strokes of `stroke_s` at 50 mm/s along x (10 mm by default) with `pause_s` between them,
// during which the tip drifts at 2 mm/s (below the 5 mm/s of moving). The logged velocity claims
// 100 mm/s throughout: speed must come from the positions.
std::vector<ServoFrame> two_strokes(double pause_s, double frame_s, double stroke_s = 0.2) {
  std::vector<ServoFrame> frames;
  const double stroke_mm_per_s = 50.0, drift_mm_per_s = 2.0;
  const double end_s = 2 * stroke_s + pause_s;
  for (int i = 0; i * frame_s <= end_s + frame_s / 2; ++i) {
    const double t_s = i * frame_s;
    double x_mm = stroke_mm_per_s * std::min(t_s, stroke_s);
    if (t_s > stroke_s) x_mm += drift_mm_per_s * (std::min(t_s, stroke_s + pause_s) - stroke_s);
    if (t_s > stroke_s + pause_s) x_mm += stroke_mm_per_s * (t_s - stroke_s - pause_s);
    ServoFrame frame = frame_at(t_s, Eigen::Vector3d(x_mm, 0.0, 0.0));
    frame.sample.velocity_mm_per_s = Eigen::Vector3d(100.0, 0.0, 0.0);
    frames.push_back(frame);
  }
  return frames;
}

TEST(TraceMetrics, TwoStrokesSeparatedByALongPauseAreTwoMovements) {
  const auto frames = two_strokes(0.5, kFrameS);
  const TraceMetrics metrics =
      compute_trace_metrics(frames, kProbeThroughout, WorkspaceMapping{}, {});
  EXPECT_EQ(metrics.movements, 2);
  const double expected_mm = 10.0 + 2.0 * 0.5 + 10.0;
  EXPECT_NEAR(metrics.path_length_mm, expected_mm,
              relative_tolerance(int(frames.size())) * expected_mm);
}

TEST(TraceMetrics, TwoStrokesSeparatedByAShortPauseAreOneMovement) {
  const auto frames = two_strokes(0.1, kFrameS);
  const TraceMetrics metrics =
      compute_trace_metrics(frames, kProbeThroughout, WorkspaceMapping{}, {});
  EXPECT_EQ(metrics.movements, 1);
}

// A pause of exactly pause_s splits ("at least this long"). Frames 2⁻¹⁰ s apart keep every time
// exact, so the gap is exactly 0.25 s and not a rounding either side of it.
TEST(TraceMetrics, APauseOfExactlyThePauseTimeSplits) {
  const double frame_s = 1.0 / 1024.0;
  TraceMetricSettings settings;
  settings.pause_s = 0.25;
  const auto exact = two_strokes(0.25, frame_s, 0.25);
  EXPECT_EQ(compute_trace_metrics(exact, kProbeThroughout, {}, settings).movements, 2);
  const auto one_frame_less = two_strokes(0.25 - frame_s, frame_s, 0.25);
  EXPECT_EQ(compute_trace_metrics(one_frame_less, kProbeThroughout, {}, settings).movements, 1);
}

// The tip moves at 10 mm/s over [0, 0.3] s with the probe and over [0.8, 1.0] s; the forceps take
// over at 0.5505 s (during the pause) and the scalpel at 0.9005 s, halfway between two frames and
// in the middle of the second stroke, which still counts as the forceps' movement.
TEST(TraceMetrics, AToolChangeSplitsThePerToolFigures) {
  const double speed_mm_per_s = 10.0;
  std::vector<ServoFrame> frames;
  for (int i = 0; i <= 1000; ++i) {
    const double t_s = i * kFrameS;
    const double x_mm = speed_mm_per_s * (std::min(t_s, 0.3) + std::max(t_s - 0.8, 0.0));
    frames.push_back(frame_at(t_s, Eigen::Vector3d(x_mm, 0.0, 0.0)));
  }
  const std::vector<ToolInterval> tools = {
      {-1.0, ToolKind::probe}, {0.5505, ToolKind::forceps}, {0.9005, ToolKind::scalpel}};

  const TraceMetrics metrics = compute_trace_metrics(frames, tools, WorkspaceMapping{}, {});

  const double tolerance_mm = relative_tolerance(1000) * 5.0;
  EXPECT_EQ(metrics.movements, 2);
  EXPECT_NEAR(metrics.path_length_mm, 5.0, tolerance_mm);
  ASSERT_EQ(metrics.per_tool.size(), 3u);
  const ToolTraceMetrics probe = metrics.per_tool.at(ToolKind::probe);
  const ToolTraceMetrics forceps = metrics.per_tool.at(ToolKind::forceps);
  const ToolTraceMetrics scalpel = metrics.per_tool.at(ToolKind::scalpel);
  EXPECT_NEAR(probe.path_length_mm, speed_mm_per_s * 0.3, tolerance_mm);
  EXPECT_NEAR(forceps.path_length_mm, speed_mm_per_s * (0.9005 - 0.8), tolerance_mm);
  EXPECT_NEAR(scalpel.path_length_mm, speed_mm_per_s * (1.0 - 0.9005), tolerance_mm);
  EXPECT_EQ(probe.movements, 1);
  EXPECT_EQ(forceps.movements, 1);
  EXPECT_EQ(scalpel.movements, 0);
}

// Scale 2 (scene m per device m), turned 90° about z and moved: 4 mm of device travel at 4 mm/s
// is 8 mm at 8 mm/s in the scene (moving, where 4 mm/s would not be), and a device force of 2.4 N
// is 1.2 N on the tissue (below the 1.5 N safe force, where 2.4 N would not be).
// The mouse: pressed at x = 0, dragged 10 mm at 20 mm/s, released (the tool lifted 30 mm: a
// jump), pressed again 50 mm away (a jump) and dragged 4 mm. The path is the two drags, 14 mm, and
// the jumps are neither path nor movement: two movements, one per drag.
TEST(TraceMetrics, JumpsOfARepositionedDeviceAreNoPath) {
  std::vector<ServoFrame> frames;
  double t_s = 0.0;
  Eigen::Vector3d at_mm = Eigen::Vector3d::Zero();
  auto add = [&](const Eigen::Vector3d& position_mm, bool jump) {
    frames.push_back(frame_at(t_s, position_mm));
    if (jump) frames.back().sample.buttons = kRepositioned;
    t_s += kFrameS;
    at_mm = position_mm;
  };
  add(at_mm, false);
  for (int i = 1; i <= 500; ++i) add(Eigen::Vector3d(0.02 * i, 0.0, 0.0), false);  // 10 mm
  add(at_mm + Eigen::Vector3d(0.0, 0.0, 30.0), true);                              // lifted
  for (int i = 0; i < 300; ++i) add(at_mm, false);                                 // 0.3 s away
  add(Eigen::Vector3d(60.0, 0.0, 0.0), true);                                      // put down
  for (int i = 1; i <= 200; ++i) add(Eigen::Vector3d(60.0 + 0.02 * i, 0.0, 0.0), false);  // 4 mm

  const TraceMetrics metrics =
      compute_trace_metrics(frames, kProbeThroughout, WorkspaceMapping{}, {});

  // Each step of 0.02 mm at positions up to 64 mm is good to about 2ε·64 mm.
  const double tolerance_mm = 700 * 2.0 * kEps * 64.0 + relative_tolerance(700) * 14.0;
  EXPECT_NEAR(metrics.path_length_mm, 14.0, tolerance_mm);
  EXPECT_NEAR(metrics.per_tool.at(ToolKind::probe).path_length_mm, 14.0, tolerance_mm);
  EXPECT_EQ(metrics.movements, 2);
}

TEST(TraceMetrics, TheMappingScaleAppliesToDistanceAndForce) {
  WorkspaceMapping mapping;
  mapping.scale = 2.0;
  mapping.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()));
  mapping.offset_m = Eigen::Vector3d(0.1, -0.2, 0.3);
  const Eigen::Vector3d device_force_n = Eigen::Vector3d(0.0, 2.4, 0.0);
  std::vector<ServoFrame> frames;
  for (int i = 0; i <= 1000; ++i) {
    const double t_s = i * kFrameS;
    frames.push_back(frame_at(t_s, Eigen::Vector3d(4.0 * t_s, 0.0, 0.0), device_force_n));
  }

  const TraceMetrics metrics = compute_trace_metrics(frames, kProbeThroughout, mapping, {});

  const double tolerance = relative_tolerance(1000);
  EXPECT_NEAR(metrics.path_length_mm, 8.0, tolerance * 8.0);
  EXPECT_EQ(metrics.movements, 1);
  EXPECT_NEAR(metrics.peak_force_n, 1.2, 4 * kEps * 1.2);  // a norm and a division
  EXPECT_NEAR(metrics.mean_force_n, 1.2, tolerance * 1.2);
  EXPECT_NEAR(metrics.rms_force_n, 1.2, tolerance * 1.2);
  EXPECT_NEAR(metrics.force_integral_n_s, 1.2, tolerance * 1.2);
  EXPECT_EQ(metrics.time_above_safe_force_s, 0.0);
  EXPECT_NEAR(metrics.task_time_s, 1.0, tolerance);  // in contact from the first frame
}

TEST(TraceMetrics, NoContactAtAllMeansNoTaskTime) {
  std::vector<ServoFrame> frames;
  for (int i = 0; i <= 1000; ++i)  // 0.01 N: below the 0.02 N of contact
    frames.push_back(frame_at(i * kFrameS, Eigen::Vector3d(20.0 * i * kFrameS, 0.0, 0.0),
                              Eigen::Vector3d(0.01, 0.0, 0.0)));

  const TraceMetrics metrics =
      compute_trace_metrics(frames, kProbeThroughout, WorkspaceMapping{}, {});

  EXPECT_EQ(metrics.task_time_s, 0.0);
  EXPECT_EQ(metrics.mean_force_n, 0.0);
  EXPECT_EQ(metrics.rms_force_n, 0.0);
  EXPECT_EQ(metrics.peak_force_n, 0.01);
  EXPECT_NEAR(metrics.force_integral_n_s, 0.01, relative_tolerance(1000) * 0.01);
  EXPECT_EQ(metrics.movements, 1);  // it moved, without touching
}

TEST(TraceMetrics, AnEmptyTraceHasNoFigures) {
  const TraceMetrics metrics = compute_trace_metrics({}, kProbeThroughout, WorkspaceMapping{}, {});
  EXPECT_EQ(metrics.path_length_mm, 0.0);
  EXPECT_EQ(metrics.movements, 0);
  EXPECT_TRUE(metrics.per_tool.empty());
  EXPECT_EQ(metrics.force_integral_n_s, 0.0);
}

// The call throws std::invalid_argument whose message contains `expected`.
void expect_refused(std::span<const ServoFrame> frames, std::span<const ToolInterval> tools,
                    const WorkspaceMapping& mapping, const TraceMetricSettings& settings,
                    const std::string& expected) {
  try {
    compute_trace_metrics(frames, tools, mapping, settings);
    ADD_FAILURE() << "accepted; expected a refusal naming \"" << expected << "\"";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find(expected), std::string::npos)
        << "message: " << error.what() << "\nexpected it to contain: " << expected;
  }
}

TEST(TraceMetrics, BadInputIsRefusedNamingTheFrame) {
  std::vector<ServoFrame> good;
  for (int i = 0; i < 10; ++i) good.push_back(frame_at(i * kFrameS, Eigen::Vector3d::Zero()));
  const WorkspaceMapping mapping;
  const TraceMetricSettings settings;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  auto repeated = good;
  repeated[5].time_s = repeated[4].time_s;
  expect_refused(repeated, kProbeThroughout, mapping, settings, "servo frame 5: time_s");
  auto backwards = good;
  backwards[7].time_s = 0.0;
  expect_refused(backwards, kProbeThroughout, mapping, settings, "servo frame 7: time_s");
  auto nan_force = good;
  nan_force[3].force_n.y() = nan;
  expect_refused(nan_force, kProbeThroughout, mapping, settings, "servo frame 3: force_n");
  auto nan_position = good;
  nan_position[2].sample.position_mm.z() = nan;
  expect_refused(nan_position, kProbeThroughout, mapping, settings, "servo frame 2: position_mm");
  auto nan_time = good;
  nan_time[8].time_s = nan;
  expect_refused(nan_time, kProbeThroughout, mapping, settings, "servo frame 8: time_s");
  auto infinite_velocity = good;
  infinite_velocity[9].sample.velocity_mm_per_s.x() = inf;
  expect_refused(infinite_velocity, kProbeThroughout, mapping, settings,
                 "servo frame 9: velocity_mm_per_s");

  const std::vector<ToolInterval> unordered = {{0.5, ToolKind::probe}, {0.2, ToolKind::forceps}};
  expect_refused(good, unordered, mapping, settings, "tool interval 1: start_s");
  WorkspaceMapping flat;
  flat.scale = 0.0;
  expect_refused(good, kProbeThroughout, flat, settings, "workspace scale");
  TraceMetricSettings negative_pause;
  negative_pause.pause_s = -0.1;
  expect_refused(good, kProbeThroughout, mapping, negative_pause, "pause_s");
}

// The hand holds no tool: a session's tool_selected events ("forceps", then "hand") become
// intervals whose hand part counts for no tool, though the tip's path still counts in all.
TEST(TraceMetrics, TheHandsStretchCountsForNoTool) {
  const double speed_mm_per_s = 10.0;
  const int intervals = 1000;
  std::vector<ServoFrame> frames;
  for (int i = 0; i <= intervals; ++i)
    frames.push_back(frame_at(i * kFrameS, Eigen::Vector3d(speed_mm_per_s * i * kFrameS, 0, 0)));
  const std::vector<SessionEvent> events = {{0.0, SessionEventKind::tool_selected, "forceps"},
                                            {0.2, SessionEventKind::grasp, ""},
                                            {0.25, SessionEventKind::tool_selected, "hand"}};
  const std::vector<ToolInterval> tools = tool_intervals(events);
  ASSERT_EQ(tools.size(), 2u);
  EXPECT_EQ(tools[0].tool, ToolKind::forceps);
  EXPECT_FALSE(tools[1].tool.has_value());

  const TraceMetrics metrics = compute_trace_metrics(frames, tools, WorkspaceMapping{}, {});
  const double tolerance_mm = relative_tolerance(intervals) * 10.0 + intervals * 2.0 * kEps * 10.0;
  EXPECT_NEAR(metrics.path_length_mm, 10.0, tolerance_mm);
  ASSERT_EQ(metrics.per_tool.size(), 1u);
  EXPECT_NEAR(metrics.per_tool.at(ToolKind::forceps).path_length_mm, 2.5, tolerance_mm);
  EXPECT_EQ(metrics.per_tool.at(ToolKind::forceps).movements, 1);
  // Under the gradable names, in the units scenario rubrics use.
  const std::vector<MetricValue> values = trace_metric_values(metrics);
  for (const MetricValue& value : values)
    EXPECT_NE(find_metric(value.name), nullptr) << value.name << " is not a gradable metric";
  EXPECT_EQ(values.at(1).name, "path_length_mm");
  EXPECT_EQ(values.at(1).value, metrics.path_length_mm);
}

// Per instrument (issue 43, item 5), on a trace whose answers follow by hand. Frames 2⁻¹⁰ s apart
// and speeds of 20 mm/s keep every time and position exact. Still for 0.5 s; 10 mm along x in
// 0.5 s (a straight movement); still for 0.5 s; 10 mm along y then 10 mm back along x, 0.5 s
// each, without a pause (one movement of path 20 mm over a straight-line distance of 10√2 mm);
// still for 0.5 s to the end at 3 s.
std::vector<ServoFrame> two_movements_and_three_rests(double frame_s) {
  std::vector<ServoFrame> frames;
  for (int i = 0; i * frame_s <= 3.0; ++i) {
    const double t_s = i * frame_s;
    const auto moved = [&](double from_s, double to_s) {
      return 20.0 * std::clamp(t_s - from_s, 0.0, to_s - from_s);
    };
    const Eigen::Vector3d x(moved(0.5, 1.0) - moved(2.0, 2.5), moved(1.5, 2.0), 0.0);
    frames.push_back(frame_at(t_s, x));
  }
  return frames;
}

TEST(TraceMetrics, EconomyOfMotionAndIdleTimeHaveTheirHandComputedValues) {
  const double frame_s = 1.0 / 1024.0;
  const std::vector<ServoFrame> frames = two_movements_and_three_rests(frame_s);
  const TraceMetrics metrics = compute_trace_metrics(frames, kProbeThroughout, {}, {});
  EXPECT_EQ(metrics.movements, 2);
  EXPECT_NEAR(metrics.path_length_mm, 30.0, 1e-12);
  ASSERT_TRUE(metrics.economy_of_motion);
  // (10 + 20) mm of path over 10 + 10√2 mm of straight lines.
  EXPECT_NEAR(*metrics.economy_of_motion, 30.0 / (10.0 + 10.0 * std::numbers::sqrt2), 1e-12);
  // The three rests of 0.5 s, each longer than the pause (0.2 s).
  EXPECT_NEAR(metrics.idle_time_s, 1.5, 1e-12);
  // The mapping scales path and straight line alike: the economy stays.
  WorkspaceMapping scaled;
  scaled.scale = 2.5;
  const TraceMetrics at_scale = compute_trace_metrics(frames, kProbeThroughout, scaled, {});
  EXPECT_NEAR(*at_scale.economy_of_motion, *metrics.economy_of_motion, 1e-12);
  // A straight stroke has economy 1; a tool that never moves has none, and is idle throughout.
  const std::vector<ServoFrame> straight(frames.begin() + 400, frames.begin() + 1100);
  EXPECT_NEAR(*compute_trace_metrics(straight, kProbeThroughout, {}, {}).economy_of_motion, 1.0,
              1e-12);
  const std::vector<ServoFrame> still(frames.begin(), frames.begin() + 500);
  const TraceMetrics resting = compute_trace_metrics(still, kProbeThroughout, {}, {});
  EXPECT_FALSE(resting.economy_of_motion);
  EXPECT_NEAR(resting.idle_time_s, 499 * frame_s, 1e-12);
  // Rests shorter than the pause are not idle.
  TraceMetricSettings long_pause;
  long_pause.pause_s = 0.6;
  EXPECT_EQ(compute_trace_metrics(frames, kProbeThroughout, {}, long_pause).idle_time_s, 0.0);
}

// Both hands: the right hand moves over [0.5, 1] s and [1.5, 2.5] s (the trace above); the left
// hand stays still and presses 0.5 N on the tissue from 0.75 s to 2 s, its force rising and
// falling within one frame interval δ, where it is above the contact force (0.02 N) for 0.96 δ.
// Both work over [0.75 − 0.96δ, 1] and [1.5, 2 + 0.96δ]; either works for 1.5 s (the right
// hand) plus the left hand's 1.25 + 1.92δ less the overlap: 2 s.
TEST(TraceMetrics, BothHandsWorkingIsTheOverlapOfEachHandsWorkOverTheirUnion) {
  const double frame_s = 1.0 / 1024.0;
  const std::vector<ServoFrame> right = two_movements_and_three_rests(frame_s);
  std::vector<ServoFrame> left;
  for (const ServoFrame& r : right) {
    const bool pressing = r.time_s >= 0.75 && r.time_s <= 2.0;
    left.push_back(frame_at(r.time_s, Eigen::Vector3d(-40.0, 0.0, 0.0),
                            Eigen::Vector3d(0.0, 0.0, pressing ? 0.5 : 0.0)));
  }
  const BimanualMetrics both = compute_bimanual_metrics({right, {}}, {left, {}}, {});
  const double crossing_s = 0.96 * frame_s;
  EXPECT_NEAR(both.both_working_s, 0.75 + 2.0 * crossing_s, 1e-12);
  EXPECT_NEAR(both.either_working_s, 2.0, 1e-12);
  EXPECT_NEAR(both.both_working_fraction, (0.75 + 2.0 * crossing_s) / 2.0, 1e-12);
  // The left hand's own figures: never moved, pressed 0.5 N.
  const TraceMetrics left_metrics = compute_trace_metrics(left, {}, {}, {});
  EXPECT_EQ(left_metrics.path_length_mm, 0.0);
  EXPECT_EQ(left_metrics.peak_force_n, 0.5);
  const std::vector<MetricValue> values = left_hand_metric_values(left_metrics);
  for (const MetricValue& value : values) {
    EXPECT_EQ(value.name.rfind("left_", 0), 0u) << value.name;
    EXPECT_NE(find_metric(value.name), nullptr) << value.name << " is not a gradable metric";
  }
  EXPECT_NE(find_metric("both_hands_working_fraction"), nullptr);
  // A hand that never works: nothing together.
  std::vector<ServoFrame> idle_left = left;
  for (ServoFrame& f : idle_left) f.force_n.setZero();
  const BimanualMetrics alone = compute_bimanual_metrics({right, {}}, {idle_left, {}}, {});
  EXPECT_EQ(alone.both_working_s, 0.0);
  EXPECT_EQ(alone.both_working_fraction, 0.0);
  // Bad input names the hand.
  left[3].force_n.x() = std::numeric_limits<double>::quiet_NaN();
  try {
    compute_bimanual_metrics({right, {}}, {left, {}}, {});
    ADD_FAILURE() << "a NaN force was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("left hand: servo frame 3: force_n", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace liversim
