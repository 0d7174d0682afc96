#pragma once
// A session as CSV (RFC 4180: fields with a comma, quote or line break are quoted, quotes doubled;
// every number at full precision, so the CSV reads back to the stored doubles): its frames, its
// events, and its metrics against the scenario's rubric. The CLI (`liversim-cli sessions export`)
// and the instructor's review window write the same files.

#include "liversim/sessions/grading.h"
#include "liversim/sessions/session_store.h"

#include <ostream>
#include <span>
#include <string>
#include <string_view>

namespace liversim {

std::string csv_field(std::string_view text);

void write_frames_csv(std::span<const ServoFrame> frames, std::ostream& out);
void write_events_csv(std::span<const SessionEvent> events, std::ostream& out);
// Every metric with its unit; those the rubric grades with their criterion and whether they
// passed, then the score (metric "score_percent", empty without one).
void write_metrics_csv(std::span<const MetricValue> metrics, const RubricResult& rubric,
                       std::ostream& out);

}  // namespace liversim
