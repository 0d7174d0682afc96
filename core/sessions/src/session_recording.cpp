#include "liversim/sessions/session_recording.h"

#include "liversim/sessions/outcome_metrics.h"
#include "liversim/sessions/trace_metrics.h"

#include <algorithm>

namespace liversim {

std::string free_practice_text(std::size_t tet_count) {
  return "free practice on the built-in liver, " + std::to_string(tet_count) + " tetrahedra";
}

std::uint64_t skip_earlier_servo_frames(ServoLoop& servo, Hand hand) {
  ServoFrame earlier;
  while (servo.next_logged_frame(hand, earlier)) {
  }
  return servo.dropped_log_frames(hand);
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
    : detector_(scenario ? scenario->task.safe_force_n : TaskSpec{}.safe_force_n),
      left_detector_(scenario ? scenario->task.safe_force_n : TaskSpec{}.safe_force_n) {
  if (scenario) lesions_ = scenario->lesions;
}

void SessionEventWatch::observe(double now_s, const SimulationSnapshot& snapshot,
                                const RealtimeStats& stats, bool cut,
                                std::vector<SessionEvent>& out) {
  const std::size_t first = out.size();
  const HandSnapshot& right = snapshot.hand(Hand::right);
  const HandSnapshot& left = snapshot.hand(Hand::left);
  const SimulationObservation scene{right.grasping,
                                    snapshot.topology_version,
                                    right.force_n.norm(),
                                    stats.rollbacks,
                                    snapshot.resected_volume_m3,
                                    snapshot.specimens_taken_out,
                                    snapshot.specimens_taken_out_m3};
  detector_.observe(now_s, scene, out);
  // A cut by the left hand's blade alone is the left hand's.
  if (left.blade_cutting && !right.blade_cutting)
    for (std::size_t i = first; i < out.size(); ++i)
      if (out[i].kind == SessionEventKind::cut) out[i].hand = Hand::left;
  // The left hand's tool: its grasps and forces only (the scene's figures held at zero, so that
  // its detector sees no cut or recovery of its own).
  SimulationObservation left_tool;
  left_tool.grasping = left.grasping;
  left_tool.tool_force_n = left.force_n.norm();
  const std::size_t left_first = out.size();
  left_detector_.observe(now_s, left_tool, out);
  for (std::size_t i = left_first; i < out.size(); ++i) out[i].hand = Hand::left;
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

std::vector<MetricValue> store_session_metrics(
    SessionStore& store, std::int64_t session, const std::optional<OutcomeTracking>& outcome,
    const Scenario* scenario, const WorkspaceMapping& mapping,
    const std::optional<WorkspaceMapping>& left_mapping) {
  std::vector<MetricValue> values;
  const std::vector<SessionEvent> events = store.events(session);
  const std::vector<ServoFrame> frames = store.frames(session);
  TraceMetricSettings trace;
  trace.safe_force_n = scenario ? scenario->task.safe_force_n : TaskSpec{}.safe_force_n;
  if (!frames.empty())
    values = trace_metric_values(
        compute_trace_metrics(frames, tool_intervals(events, Hand::right), mapping, trace));
  if (left_mapping) {
    const std::vector<ServoFrame> left_frames = store.frames(session, Hand::left);
    if (!left_frames.empty()) {
      const std::vector<MetricValue> left = left_hand_metric_values(compute_trace_metrics(
          left_frames, tool_intervals(events, Hand::left), *left_mapping, trace));
      values.insert(values.end(), left.begin(), left.end());
      values.push_back(
          {"both_hands_working_fraction",
           compute_bimanual_metrics({frames, mapping}, {left_frames, *left_mapping}, trace)
               .both_working_fraction});
    }
  }
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
