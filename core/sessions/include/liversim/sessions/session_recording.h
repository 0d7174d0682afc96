#pragma once
// Recording a session of a scene whose tool a device drives through the haptic servo, as the
// workstation does and `liversim-cli record` does headless: the same steps, in one place. The
// session's frames are the servo's from its beginning; the simulation's outcome is tracked; each
// display frame's events are recorded; at the end its metrics are computed from what was stored
// and stored with it (docs/session-storage.md, docs/session-metrics.md).

#include "liversim/haptics/haptics.h"
#include "liversim/haptics/servo_loop.h"
#include "liversim/scenario/scenario.h"
#include "liversim/sessions/session_events.h"
#include "liversim/sessions/session_store.h"
#include "liversim/simulation/realtime_simulation.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace liversim {

// The scenario text of a free-practice session on the built-in liver: it has no file, so the text
// names the scene it ran.
std::string free_practice_text(std::size_t tet_count);

// A session's frames are those the servo logs from now on: drops the frames the device in `hand`
// queued before (since it started; the mouse's until its first press). Returns how many frames its
// log has dropped so far: the session's dropped-frame figure counts from there.
std::uint64_t skip_earlier_servo_frames(ServoLoop& servo, Hand hand = Hand::right);

// From the simulation's next cycle on, tracks what the session does to the tissue (damage, the
// retracted lobe's lift, resection) with the scenario's thresholds; none: free practice's
// defaults.
void track_session_outcome(RealtimeSimulation& simulation, const Scenario* scenario);

// The events a session's display frames show: SessionEventDetector's at the task's safe force
// (free practice: the default), and each of the scenario's lesions that the cut surface meets,
// once. A grasp, a release or an excessive force is of the hand whose tool it was; a cut, of the
// hand whose blade was cutting (the right one's when both were); the rest, of the scene (filed
// under the right hand).
class SessionEventWatch {
 public:
  explicit SessionEventWatch(const Scenario* scenario);
  // A display frame at `now_s` (servo clock); `cut`: its model is a cut newer than the one shown
  // before. Appends the events to `out`.
  void observe(double now_s, const SimulationSnapshot& snapshot, const RealtimeStats& stats,
               bool cut, std::vector<SessionEvent>& out);

 private:
  SessionEventDetector detector_;
  SessionEventDetector left_detector_;  // the left hand's grasps and forces only
  std::vector<LesionSpec> lesions_;
  std::set<std::string> breached_;  // lesions a cut has met, reported once each
};

// The metrics of a session that has ended: of its trace, from the frames and tool choices the
// store holds (a long session's hundreds of megabytes are read here, so a UI calls this off its
// thread), and of its simulation's outcome when it was tracked; stored with the session and
// returned. `scenario`: the one it ran (none: free practice); `mapping`: its device → scene;
// `left_mapping`: the left hand's device's, in a session with one in each hand (its figures are
// then the left_ metrics, and both_hands_working_fraction). Throws StorageError.
std::vector<MetricValue> store_session_metrics(
    SessionStore& store, std::int64_t session, const std::optional<OutcomeTracking>& outcome,
    const Scenario* scenario, const WorkspaceMapping& mapping,
    const std::optional<WorkspaceMapping>& left_mapping = std::nullopt);

}  // namespace liversim
