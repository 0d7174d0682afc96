// Session events found from what the simulation showed at successive display frames (issue 10).
#include "liversim/sessions/session_events.h"

#include <gtest/gtest.h>

namespace liversim {
namespace {

std::vector<SessionEventKind> kinds(const std::vector<SessionEvent>& events) {
  std::vector<SessionEventKind> result;
  for (const SessionEvent& e : events) result.push_back(e.kind);
  return result;
}

TEST(SessionEvents, GraspReleaseCutExcessiveForceAndRecoveryEachOnceWhenTheyHappen) {
  SessionEventDetector detector(1.5, 0.9);
  std::vector<SessionEvent> events;
  SimulationObservation o;
  o.topology_version = 3;  // cuts before the session are not its events
  o.rollbacks = 2;
  o.resected_volume_m3 = 1e-6;
  detector.observe(0.0, o, events);
  EXPECT_TRUE(events.empty());
  o.grasping = true;
  detector.observe(0.1, o, events);
  o.tool_force_n = 1.6;  // above 1.5 N
  detector.observe(0.2, o, events);
  o.tool_force_n = 1.4;  // below, but not below 0.9 × 1.5 = 1.35: not re-armed
  detector.observe(0.3, o, events);
  o.tool_force_n = 1.7;
  detector.observe(0.4, o, events);
  o.tool_force_n = 1.3;  // re-armed
  detector.observe(0.5, o, events);
  o.tool_force_n = 1.8;
  detector.observe(0.6, o, events);
  o.grasping = false;
  o.topology_version = 4;
  o.resected_volume_m3 = 1e-6 + 2.5e-7;
  o.rollbacks = 3;
  detector.observe(0.7, o, events);
  detector.observe(0.8, o, events);  // nothing new
  const std::vector<SessionEventKind> expected{SessionEventKind::grasp,
                                               SessionEventKind::excessive_force,
                                               SessionEventKind::excessive_force,
                                               SessionEventKind::release,
                                               SessionEventKind::cut,
                                               SessionEventKind::simulation_recovery};
  EXPECT_EQ(kinds(events), expected);
  EXPECT_EQ(events[1].time_s, 0.2);
  EXPECT_EQ(events[1].detail, "1.6 N");
  EXPECT_EQ(events[2].time_s, 0.6);
  EXPECT_EQ(events[4].detail, "resected 250 mm3");
  EXPECT_EQ(events[5].detail, "1 rollback(s)");
}

// A specimen taken out changes the model as a cut does; it is its own event, and a cut in the
// same frame is still reported.
TEST(SessionEvents, ASpecimenTakenOutIsItsOwnEventNotACut) {
  SessionEventDetector detector;
  std::vector<SessionEvent> events;
  SimulationObservation o;
  o.topology_version = 5;
  detector.observe(0.0, o, events);
  o.topology_version = 6;
  o.specimens_taken_out = 1;
  o.specimens_taken_out_m3 = 2.4e-5;
  detector.observe(0.1, o, events);
  ASSERT_EQ(kinds(events), std::vector<SessionEventKind>{SessionEventKind::specimen_removed});
  EXPECT_EQ(events[0].detail, "2.4e+04 mm3");
  EXPECT_EQ(session_event_name(events[0].kind), "specimen_removed");
  events.clear();
  o.topology_version = 8;  // a cut and another take-out between two frames
  o.specimens_taken_out = 2;
  detector.observe(0.2, o, events);
  EXPECT_EQ(kinds(events), (std::vector<SessionEventKind>{SessionEventKind::specimen_removed,
                                                          SessionEventKind::cut}));
}

TEST(SessionEvents, AGraspOrExcessiveForceAlreadyOnAtTheStartIsReported) {
  SessionEventDetector detector(1.5);
  std::vector<SessionEvent> events;
  detector.observe(5.0, {true, 0, 2.0, 0, 0.0}, events);
  const std::vector<SessionEventKind> expected{SessionEventKind::grasp,
                                               SessionEventKind::excessive_force};
  EXPECT_EQ(kinds(events), expected);
}

}  // namespace
}  // namespace liversim
