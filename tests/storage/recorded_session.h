#pragma once
// A finished session as a workstation records it, written to a sessions database: for the
// training centre's tests and its load bench.

#include "liversim/engine/integrator.h"
#include "liversim/storage/sqlite_session_store.h"
#include "synthetic_frames.h"

#include <algorithm>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace liversim::testing {

// What a workstation recorded: a finished session with frames in 50-frame chunks (as the
// recorder commits them), inputs, events, metrics and how to replay it; with a device in the left
// hand too, its frames (in 40-frame chunks), its tool's events and its servo figures.
struct Recorded {
  std::int64_t id = 0;
  std::vector<ServoFrame> frames;
  std::vector<ServoFrame> left_frames;  // none: a one-handed session
  std::optional<SessionServoFigures> left_servo;
  std::vector<SimulationInput> inputs;
  std::vector<SessionEvent> events;
  std::vector<MetricValue> metrics;
  ReplaySetup replay;
};

inline Recorded record_session(SqliteSessionStore& store, const std::string& trainee,
                               std::size_t frame_count, unsigned seed,
                               std::size_t left_frame_count = 0) {
  Recorded r;
  r.frames = synthetic_frames(frame_count, seed);
  r.left_frames = synthetic_frames(left_frame_count, seed + 100);
  r.replay.built_in_liver_tets = 2500;
  r.replay.integrator.kind = IntegratorKind::dopri5;
  r.replay.integrator.tolerance_m = 2e-7;
  SessionStart start{trainee,    "Wedge resection",        "{\"title\": \"Wedge resection\"}",
                     "Scripted", 1'795'000'000'000 + seed, std::nullopt,
                     r.replay};
  WorkspaceMapping mapping;
  mapping.scale = 1.25;
  start.mapping = mapping;
  if (left_frame_count > 0) {
    LeftHandDevice left{"Scripted left", mapping};
    left.mapping.scale = 2.0;
    left.mapping.offset_m = {-0.05, 0.0, 0.01};
    start.left_hand = left;
  }
  r.id = store.begin_session(start);
  for (std::size_t first = 0; first < r.left_frames.size(); first += 40) {
    const std::size_t count = std::min<std::size_t>(40, r.left_frames.size() - first);
    store.append_frames(r.id, Hand::left, std::span(r.left_frames).subspan(first, count));
    store.commit();
  }
  for (std::size_t first = 0; first < r.frames.size(); first += 50) {
    const std::size_t count = std::min<std::size_t>(50, r.frames.size() - first);
    store.append_frames(r.id, std::span(r.frames).subspan(first, count));
    SimulationInput cycle{SimulationInput::Kind::cycle, std::nullopt, {}, 3, true,
                          r.frames[first].time_s};
    r.inputs.push_back(cycle);
    store.append_inputs(r.id, std::span(&r.inputs.back(), 1));
    store.commit();
  }
  r.events = {{0.01, SessionEventKind::tool_selected, "scalpel"},
              {0.02, SessionEventKind::cut, "Robert'); DROP TABLE sessions;--"}};
  if (left_frame_count > 0) {
    r.events.push_back({0.015, SessionEventKind::tool_selected, "forceps", Hand::left});
    r.events.push_back({0.03, SessionEventKind::grasp, "", Hand::left});
  }
  store.append_events(r.id, r.events);
  store.commit();
  // As read back: in time order.
  std::stable_sort(
      r.events.begin(), r.events.end(),
      [](const SessionEvent& a, const SessionEvent& b) { return a.time_s < b.time_s; });
  SessionServoFigures servo;
  servo.ticks = frame_count;
  servo.rate_hz = 1000.0;
  if (left_frame_count > 0) {
    SessionServoFigures left = servo;
    left.force_clamps = 3;
    left.dropped_frames = 1;
    r.left_servo = left;
  }
  store.end_session(r.id, 1'795'000'100'000, servo, r.left_servo);
  r.metrics = {{"path_length_m", 0.25 + seed}, {"peak_force_n", 1.5}};
  store.store_metrics(r.id, r.metrics);
  return r;
}

}  // namespace liversim::testing
