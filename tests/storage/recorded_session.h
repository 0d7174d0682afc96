#pragma once
// A finished session as a workstation records it, written to a sessions database: for the
// training centre's tests and its load bench.

#include "liversim/engine/integrator.h"
#include "liversim/storage/sqlite_session_store.h"
#include "synthetic_frames.h"

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace liversim::testing {

// What a workstation recorded: a finished session with frames in 50-frame chunks (as the
// recorder commits them), inputs, events, metrics and how to replay it.
struct Recorded {
  std::int64_t id = 0;
  std::vector<ServoFrame> frames;
  std::vector<SimulationInput> inputs;
  std::vector<SessionEvent> events;
  std::vector<MetricValue> metrics;
  ReplaySetup replay;
};

inline Recorded record_session(SqliteSessionStore& store, const std::string& trainee,
                               std::size_t frame_count, unsigned seed) {
  Recorded r;
  r.frames = synthetic_frames(frame_count, seed);
  r.replay.built_in_liver_tets = 2500;
  r.replay.integrator.kind = IntegratorKind::dopri5;
  r.replay.integrator.tolerance_m = 2e-7;
  SessionStart start{trainee,    "Wedge resection",        "{\"title\": \"Wedge resection\"}",
                     "Scripted", 1'795'000'000'000 + seed, std::nullopt,
                     r.replay};
  WorkspaceMapping mapping;
  mapping.scale = 1.25;
  start.mapping = mapping;
  r.id = store.begin_session(start);
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
  store.append_events(r.id, r.events);
  store.commit();
  SessionServoFigures servo;
  servo.ticks = frame_count;
  servo.rate_hz = 1000.0;
  store.end_session(r.id, 1'795'000'100'000, servo);
  r.metrics = {{"path_length_m", 0.25 + seed}, {"peak_force_n", 1.5}};
  store.store_metrics(r.id, r.metrics);
  return r;
}

}  // namespace liversim::testing
