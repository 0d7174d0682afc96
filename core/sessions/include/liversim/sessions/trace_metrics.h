#pragma once
// Gradable metrics that come from the servo trace alone (the frames a session logs at ~1 kHz):
// path length, movements, task time and the force figures. Each is defined precisely in
// docs/session-metrics.md. The frames are samples of piecewise-linear signals (tool-tip position,
// tissue force): time integrals and times in a state are exact for that interpolation.

#include "liversim/haptics/haptics.h"
#include "liversim/haptics/servo_loop.h"
#include "liversim/interaction/tools.h"

#include <map>
#include <optional>
#include <span>

namespace liversim {

// The tool in use from `start_s` (servo clock) on, until the next interval's start; none: the
// hand (the device holds no tool).
struct ToolInterval {
  double start_s = 0.0;
  std::optional<ToolKind> tool = ToolKind::probe;
};

struct TraceMetricSettings {
  double contact_force_n = 0.02;       // tissue force above this = in contact
  double safe_force_n = 1.5;           // the scenario's safe-force threshold
  double moving_speed_mm_per_s = 5.0;  // scene tool-tip speed above this = moving
  double pause_s = 0.2;  // motion separated by a pause at least this long = two movements
};

struct ToolTraceMetrics {
  double path_length_mm = 0.0;
  int movements = 0;
};

struct TraceMetrics {
  double task_time_s = 0.0;     // first contact to the last frame (0 with no contact)
  double path_length_mm = 0.0;  // scene tool tip, all tools
  int movements = 0;            // all tools
  // The movements' path over their straight-line distance (≥ 1); none without a movement.
  std::optional<double> economy_of_motion;
  double idle_time_s = 0.0;                       // still for at least the pause time
  std::map<ToolKind, ToolTraceMetrics> per_tool;  // tools that were in use
  double peak_force_n = 0.0;                      // tissue force
  double mean_force_n = 0.0;                      // over the time in contact (0 with none)
  double rms_force_n = 0.0;                       // over the time in contact (0 with none)
  double force_integral_n_s = 0.0;                // ∫|F| dt over the session
  double peak_force_rate_n_per_s = 0.0;           // largest |Δ|F||/Δt between consecutive frames
  double time_above_safe_force_s = 0.0;
};

// What two hands did together (a session with a device in each hand): each hand works while its
// tool tip moves or touches the tissue (docs/session-metrics.md, "Both hands").
struct BimanualMetrics {
  double either_working_s = 0.0;       // at least one hand works
  double both_working_s = 0.0;         // both hands work at once
  double both_working_fraction = 0.0;  // both over either (0 when neither ever works)
};

// One hand's trace: its frames (in time order) and its device's mapping.
struct HandTrace {
  std::span<const ServoFrame> frames;
  WorkspaceMapping mapping;
};
// Throws std::invalid_argument as compute_trace_metrics does, naming the hand.
BimanualMetrics compute_bimanual_metrics(const HandTrace& right, const HandTrace& left,
                                         const TraceMetricSettings& settings);

// `frames` in time order; `tools` in order of start (may be empty: no per-tool figures). Throws
// std::invalid_argument naming the frame (or tool interval) index for times that do not increase
// and for NaN or infinite data, and naming the setting for a bad mapping or setting.
TraceMetrics compute_trace_metrics(std::span<const ServoFrame> frames,
                                   std::span<const ToolInterval> tools,
                                   const WorkspaceMapping& mapping,
                                   const TraceMetricSettings& settings);

}  // namespace liversim
