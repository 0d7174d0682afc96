#pragma once
// What the two session stores (SQLite, PostgreSQL) read alike from their rows: one query's
// columns and their decoding, so that the stores differ only in how they talk to their engine.
// A Row has integer(c), real(c), text(c) and is_null(c) for its columns c = 0, 1, ...

#include "liversim/sessions/session_store.h"

#include <array>
#include <chrono>
#include <cstdint>
#include <iterator>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace liversim::stored_rows {

inline std::int64_t unix_ms_now() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Column names in both schemas.
inline constexpr const char* kServoColumns =
    "servo_ticks, servo_rate_hz, servo_period_p50_ms, servo_period_p99_ms, servo_period_max_ms, "
    "missed_deadlines, force_clamps, stiffness_clamps, rate_limited, watchdog_trips, "
    "device_faults, dropped_frames";
inline constexpr const char* kMappingColumns =
    "mapping_scale, mapping_rotation_w, mapping_rotation_x, mapping_rotation_y, "
    "mapping_rotation_z, mapping_offset_x_m, mapping_offset_y_m, mapping_offset_z_m";

// A comma-separated column list with each name prefixed (the left hand's columns are the right
// hand's with "left_" before them).
inline std::string prefixed_columns(std::string_view columns, std::string_view prefix) {
  std::string result(prefix);
  for (const char c : columns) {
    result += c;
    if (c == ' ') result += prefix;
  }
  return result;
}

// The left hand's device (schema 7 on, PostgreSQL 4 on): its name (null: a one-handed session),
// frame count, mapping and servo figures, in sessions.
inline const std::string kLeftMappingColumns = prefixed_columns(kMappingColumns, "left_");
inline const std::string kLeftServoColumns = prefixed_columns(kServoColumns, "left_");

// The sessions with what a SessionSummary holds, read by session_summary(); the caller adds its
// WHERE (parameter 1: a trainee's name or null for all) and ORDER BY.
inline const std::string kSessionSummarySelect =
    "SELECT s.id, p.name, c.title, c.sha256, s.device, s.started_unix_ms, s.ended_unix_ms, "
    "s.status, s.frame_count, s.servo_ticks, s.servo_rate_hz, s.servo_period_p50_ms, "
    "s.servo_period_p99_ms, s.servo_period_max_ms, s.missed_deadlines, s.force_clamps, "
    "s.stiffness_clamps, s.rate_limited, s.watchdog_trips, s.device_faults, s.dropped_frames, "
    "s.mapping_scale, s.mapping_rotation_w, s.mapping_rotation_x, s.mapping_rotation_y, "
    "s.mapping_rotation_z, s.mapping_offset_x_m, s.mapping_offset_y_m, s.mapping_offset_z_m, "
    "CAST(s.uuid AS TEXT), s.left_device, s.left_frame_count, " +
    prefixed_columns(kLeftMappingColumns, "s.") + ", " + prefixed_columns(kLeftServoColumns, "s.") +
    " FROM sessions s JOIN people p ON p.id = s.trainee_id "
    "JOIN scenarios c ON c.id = s.scenario_id ";

// A mapping's values in kMappingColumns' order.
inline std::array<double, 8> mapping_values(const WorkspaceMapping& m) {
  return {m.scale,        m.rotation.w(), m.rotation.x(), m.rotation.y(),
          m.rotation.z(), m.offset_m.x(), m.offset_m.y(), m.offset_m.z()};
}

// An event from its stored columns (kind and hand by name); throws StorageError naming a kind or
// hand this version does not know (the caller adds which session).
inline SessionEvent session_event(double time_s, const std::string& kind, std::string detail,
                                  const std::string& hand) {
  const std::optional<SessionEventKind> known = session_event_kind(kind);
  if (!known) throw StorageError("has an event of unknown kind \"" + kind + "\"");
  const std::optional<Hand> of = hand_named(hand);
  if (!of) throw StorageError("has an event of an unknown hand \"" + hand + "\"");
  return {time_s, *known, std::move(detail), *of};
}

// Servo figures from the 12 columns from `first` on (kServoColumns' order).
template <typename Row>
SessionServoFigures servo_figures_of(const Row& row, int first) {
  const auto count = [&](int column) {
    return static_cast<std::uint64_t>(row.integer(first + column));
  };
  SessionServoFigures f;
  f.ticks = count(0);
  f.rate_hz = row.real(first + 1);
  f.period_p50_ms = row.real(first + 2);
  f.period_p99_ms = row.real(first + 3);
  f.period_max_ms = row.real(first + 4);
  f.missed_deadlines = count(5);
  f.force_clamps = count(6);
  f.stiffness_clamps = count(7);
  f.rate_limited = count(8);
  f.watchdog_trips = count(9);
  f.device_faults = count(10);
  f.dropped_frames = count(11);
  return f;
}

// A mapping from the 8 columns from `first` on (kMappingColumns' order).
template <typename Row>
WorkspaceMapping mapping_of(const Row& row, int first) {
  WorkspaceMapping m;
  m.scale = row.real(first);
  m.rotation = Eigen::Quaterniond(row.real(first + 1), row.real(first + 2), row.real(first + 3),
                                  row.real(first + 4));
  m.offset_m = Eigen::Vector3d(row.real(first + 5), row.real(first + 6), row.real(first + 7));
  return m;
}

template <typename Row>
SessionSummary session_summary(const Row& row) {
  SessionSummary s;
  s.id = row.integer(0);
  s.trainee = row.text(1);
  s.scenario_title = row.text(2);
  s.scenario_sha256 = row.text(3);
  s.device = row.text(4);
  s.started_unix_ms = row.integer(5);
  if (!row.is_null(6)) s.ended_unix_ms = row.integer(6);
  const std::string status = row.text(7);
  s.status = status == "complete"    ? SessionStatus::complete
             : status == "recording" ? SessionStatus::recording
                                     : SessionStatus::incomplete;
  s.frame_count = row.integer(8);
  if (!row.is_null(9)) s.servo = servo_figures_of(row, 9);
  if (!row.is_null(21)) s.mapping = mapping_of(row, 21);
  if (!row.is_null(29)) s.uuid = row.text(29);
  if (!row.is_null(30)) {
    s.left_hand = LeftHandDevice{row.text(30), mapping_of(row, 32)};
    s.left_frame_count = row.integer(31);
    if (!row.is_null(40)) s.left_servo = servo_figures_of(row, 40);
  }
  return s;
}

// A grade from columns first.. first+4: instructor's name, graded_unix_ms, score, grade, comment.
template <typename Row>
SessionGrade session_grade(const Row& row, int first = 0) {
  SessionGrade g;
  g.instructor = row.text(first);
  g.graded_unix_ms = row.integer(first + 1);
  if (!row.is_null(first + 2)) g.score_percent = row.real(first + 2);
  g.grade = row.text(first + 3);
  g.comment = row.text(first + 4);
  return g;
}

// Appends a stored chunk's items to those read so far, checking that it follows them and that
// its layout is the one this version reads; throws StorageError naming what is wrong (`items`:
// "frames", "inputs").
template <typename Item, typename Decode>
void append_chunk(std::vector<Item>& read, std::int64_t first, std::int64_t layout,
                  int known_layout, std::span<const std::uint8_t> bytes, const std::string& items,
                  Decode decode) {
  if (first != static_cast<std::int64_t>(read.size()))
    throw StorageError(items + " " + std::to_string(read.size()) + " to " + std::to_string(first) +
                       " are missing");
  if (layout < 1 || layout > known_layout)  // each version reads every layout before its own
    throw StorageError("a chunk of " + items + " has layout " + std::to_string(layout) +
                           ", which this version cannot read",
                       StorageProblem::newer_version);
  std::vector<Item> part = decode(bytes);
  std::move(part.begin(), part.end(), std::back_inserter(read));
}

}  // namespace liversim::stored_rows
