#pragma once
// A finished session on its way from a workstation's SQLite file to the training centre's server:
// what it is (keyed by its UUID, so that an upload done twice stores it once) and its chunks as
// stored, not decoded (exact, and no work), streamed one at a time.

#include "liversim/sessions/session_store.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace liversim {

// A chunk of frames or of simulation inputs as stored (docs/session-storage.md): items
// first..first+count-1, in its layout. Frame chunks have their first and last time.
struct StoredChunk {
  std::int64_t first = 0;
  std::int64_t count = 0;
  double first_time_s = 0.0;
  double last_time_s = 0.0;
  int layout = 0;
  std::vector<std::uint8_t> data;
};

// Calls the sink with each chunk in order.
using ChunkSink = std::function<void(const StoredChunk&)>;
using ChunkSource = std::function<void(const ChunkSink&)>;

struct SessionTransfer {
  SessionSummary summary;  // keyed by its uuid; its id is the sender's and is not kept
  std::string scenario_text;
  std::int64_t input_count = 0;
  std::optional<ReplaySetup> replay;
  std::vector<SessionEvent> events;
  std::vector<MetricValue> metrics;
  ChunkSource frame_chunks;
  ChunkSource left_frame_chunks;  // none for a one-handed session (summary.left_hand)
  ChunkSource input_chunks;
};

// A grade as it travels between stores: whose session (by UUID) and its own UUID, so that a
// grade pulled twice is kept once.
struct SharedGrade {
  std::string session_uuid;
  std::string grade_uuid;
  SessionGrade grade;
  bool operator==(const SharedGrade&) const = default;
};

// A new random (version 4) UUID, "xxxxxxxx-xxxx-4xxx-yxxx-xxxxxxxxxxxx".
std::string new_uuid();

}  // namespace liversim
