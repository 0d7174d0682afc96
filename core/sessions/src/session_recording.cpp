#include "liversim/sessions/session_recording.h"

#include "liversim/sessions/outcome_metrics.h"
#include "liversim/sessions/trace_metrics.h"

#include <algorithm>

namespace liversim {

std::string free_practice_text(std::size_t tet_count) {
  return "free practice on the built-in liver, " + std::to_string(tet_count) + " tetrahedra";
}

std::uint64_t skip_earlier_servo_frames(ServoLoop& servo) {
  ServoFrame earlier;
  while (servo.next_logged_frame(earlier)) {
  }
  return servo.dropped_log_frames();
}

void track_session_outcome(RealtimeSimulation& simulation, const Scenario* scenario) {
  std::optional<Eigen::Vector3d> lift_point_m;
  if (scenario && scenario->task.kind == TaskKind::retract_lobe)
    lift_point_m = to_metres(scenario->task.grasp_point_mm);
  const TaskSpec task = scenario ? scenario->task : TaskSpec{};
  simulation.track_outcome(lift_point_m,
                           {task.damage_tension_strain, task.damage_compression_strain});
}

SessionEventWatch::SessionEventWatch(const Scenario* scenario)
    : detector_(scenario ? scenario->task.safe_force_n : TaskSpec{}.safe_force_n) {
  if (scenario) lesions_ = scenario->lesions;
}

void SessionEventWatch::observe(double now_s, const SimulationSnapshot& snapshot,
                                const RealtimeStats& stats, bool cut,
                                std::vector<SessionEvent>& out) {
  detector_.observe(
      now_s,
      {snapshot.hand(Hand::right).grasping, snapshot.topology_version,
       snapshot.hand(Hand::right).force_n.norm(), stats.rollbacks, snapshot.resected_volume_m3,
       snapshot.specimens_taken_out, snapshot.specimens_taken_out_m3},
      out);
  // A cut into a lesion: checked against the whole cut surface, each lesion reported once.
  if (!cut || !snapshot.model || lesions_.empty()) return;
  const auto surface = cut_surface_at_rest_m(*snapshot.model);
  for (const LesionSpec& lesion : lesions_) {
    if (breached_.count(lesion.name)) continue;
    const Ellipsoid ellipsoid = lesion_ellipsoid(lesion);
    if (std::any_of(surface.begin(), surface.end(), [&](const auto& triangle) {
          return triangle_meets_ellipsoid(triangle, ellipsoid);
        })) {
      breached_.insert(lesion.name);
      out.push_back({now_s, SessionEventKind::lesion_breach, lesion.name});
    }
  }
}

std::vector<MetricValue> store_session_metrics(SessionStore& store, std::int64_t session,
                                               const std::optional<OutcomeTracking>& outcome,
                                               const Scenario* scenario,
                                               const WorkspaceMapping& mapping) {
  std::vector<MetricValue> values;
  const std::vector<SessionEvent> events = store.events(session);
  const std::vector<ServoFrame> frames = store.frames(session);
  TraceMetricSettings trace;
  trace.safe_force_n = scenario ? scenario->task.safe_force_n : TaskSpec{}.safe_force_n;
  if (!frames.empty())
    values =
        trace_metric_values(compute_trace_metrics(frames, tool_intervals(events), mapping, trace));
  if (outcome) {
    const std::vector<MetricValue> simulated = outcome_metric_values(
        compute_outcome_metrics(*outcome->initial_model, *outcome->model, outcome->tracker,
                                scenario, lesion_marks(events)),
        scenario);
    values.insert(values.end(), simulated.begin(), simulated.end());
  }
  if (!values.empty()) store.store_metrics(session, values);
  return values;
}

}  // namespace liversim
