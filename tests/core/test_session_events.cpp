// Session events found from what the simulation showed at successive display frames (issue 10).
#include "liversim/sessions/session_events.h"
#include "liversim/sessions/session_recording.h"

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

// Two hands (issue 43): each hand's grasps and forces are its own events, a cut is the hand's
// whose blade cut, and what the scene does is reported once, under the right hand.
TEST(SessionEvents, EachHandsGraspsForcesAndCutsAreTaggedWithTheHand) {
  SessionEventWatch watch(nullptr);  // free practice: the default safe force
  const double safe_n = TaskSpec{}.safe_force_n;
  SimulationSnapshot shown;
  RealtimeStats stats;
  std::vector<SessionEvent> events;
  watch.observe(0.0, shown, stats, false, events);
  EXPECT_TRUE(events.empty());

  // The left hand's forceps close and pull too hard; the right hand does nothing.
  shown.hands[hand_index(Hand::left)].grasping = true;
  shown.hands[hand_index(Hand::left)].force_n = Eigen::Vector3d(0.0, 0.0, safe_n + 0.5);
  watch.observe(0.1, shown, stats, false, events);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, SessionEventKind::grasp);
  EXPECT_EQ(events[0].hand, Hand::left);
  EXPECT_EQ(events[1].kind, SessionEventKind::excessive_force);
  EXPECT_EQ(events[1].hand, Hand::left);

  // The left hand's blade cuts (its forceps let go): a cut of the left hand, a release of the
  // left hand; a recovery of the scene, once.
  events.clear();
  shown.hands[hand_index(Hand::left)].grasping = false;
  shown.hands[hand_index(Hand::left)].blade_cutting = true;
  shown.topology_version = 1;
  stats.rollbacks = 1;
  watch.observe(0.2, shown, stats, false, events);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].kind, SessionEventKind::cut);
  EXPECT_EQ(events[0].hand, Hand::left);
  EXPECT_EQ(events[1].kind, SessionEventKind::simulation_recovery);
  EXPECT_EQ(events[1].hand, Hand::right);
  EXPECT_EQ(events[2].kind, SessionEventKind::release);
  EXPECT_EQ(events[2].hand, Hand::left);

  // Both blades in the tissue: the cut is filed under the right hand.
  events.clear();
  shown.hands[hand_index(Hand::right)].blade_cutting = true;
  shown.topology_version = 2;
  watch.observe(0.3, shown, stats, false, events);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, SessionEventKind::cut);
  EXPECT_EQ(events[0].hand, Hand::right);
}

}  // namespace
}  // namespace liversim
