#pragma once
// What a training session leaves behind: the servo's frames at ~1 kHz, the events (grasp, cut,
// excessive force...) and, at its end, the servo's statistics; and the storage they go to, behind
// a small interface (SqliteSessionStore is the embedded one). docs/session-storage.md describes
// the schema and the layout of the frame chunks.

#include "liversim/haptics/haptics.h"
#include "liversim/haptics/servo_loop.h"
#include "liversim/interaction/simulation_input.h"
#include "liversim/sessions/trace_metrics.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace liversim {

// What kind of trouble a storage error is, so that an interface can say what to do about it.
enum class StorageProblem {
  other,
  unreachable,     // cannot be opened: no such folder, no permission, the disk gone
  read_only,       // the file or its folder cannot be written
  disk_full,       // the disk, or the database's page limit, is full
  damaged,         // the file is corrupt
  not_a_database,  // not a (LiverSim) database
  newer_version,   // written by a newer LiverSim
  deleted,         // deleted or replaced while in use
  refused,         // a server refused the login or the action (wrong password, no permission)
};

// A storage failure: names the database file and what is wrong with it (read-only, damaged, full,
// written by a newer version...), and its kind.
class StorageError : public std::runtime_error {
 public:
  explicit StorageError(const std::string& what, StorageProblem problem = StorageProblem::other)
      : std::runtime_error(what), problem_(problem) {}
  StorageProblem problem() const { return problem_; }

 private:
  StorageProblem problem_;
};

enum class SessionEventKind {
  grasp,
  release,
  cut,
  excessive_force,
  lesion_breach,
  simulation_recovery,
  device_fault,
  tool_selected,  // detail: the tool's name
  lesion_marked,  // palpation: the trainee's mark, detail "x y z" (rest, mm)
  // The Accuracy panel changed the integrator (detail: its name and step); a replay of the
  // session's input stops there.
  integrator_changed,
  // The Material panel changed the tissue (detail: the parenchyma's new parameters); a replay of
  // the session's input stops there too.
  material_changed,
  // Gravity was switched on or off (detail: describe_gravity); a replay stops there too.
  gravity_changed,
  // A free body was taken out of the field: lifted out, or Session ▸ Remove Specimen (detail: its
  // rest volume in mm³).
  specimen_removed,
};
std::string_view session_event_name(SessionEventKind kind);
std::optional<SessionEventKind> session_event_kind(std::string_view name);

struct SessionEvent {
  double time_s = 0.0;  // servo clock, as the frames
  SessionEventKind kind = SessionEventKind::grasp;
  std::string detail;
  // Whose tool or device it is of (schema 7 on; every event before is the right hand's, the only
  // one then). Events of the whole scene (a recovery, a change of material, a specimen taken out)
  // are filed under the right hand, the one every session has.
  Hand hand = Hand::right;
  bool operator==(const SessionEvent&) const = default;
};

// recording: a writer has it open (or had, until it was killed: the next writer to open the
// database marks it incomplete); complete: ended normally.
enum class SessionStatus { recording, complete, incomplete };
std::string_view session_status_name(SessionStatus status);

// The second device of a two-handed session (issue 43): the left hand's.
struct LeftHandDevice {
  std::string device;        // its name
  WorkspaceMapping mapping;  // its device → scene
};

struct SessionStart {
  std::string trainee;  // a person of role trainee, added on first use
  std::string scenario_title;
  std::string scenario_text;  // the exact scenario file content the session runs
  std::string device;         // the haptic device's name
  std::int64_t started_unix_ms = 0;
  // Device → scene for the session (schema 2 on): tissue forces are device forces / its scale.
  std::optional<WorkspaceMapping> mapping;
  // How to build the session's scene again (schema 3 on); none: the session cannot be replayed
  // (its simulation input is not recorded).
  std::optional<ReplaySetup> replay;
  // A device in the left hand too (schema 7 on): its frames are recorded beside the right's.
  std::optional<LeftHandDevice> left_hand = std::nullopt;
};

// The servo's figures of a session (ServoStats reduced to what is kept).
struct SessionServoFigures {
  std::uint64_t ticks = 0;
  double rate_hz = 0.0;
  double period_p50_ms = 0.0, period_p99_ms = 0.0, period_max_ms = 0.0;
  std::uint64_t missed_deadlines = 0, force_clamps = 0, stiffness_clamps = 0, rate_limited = 0,
                watchdog_trips = 0, device_faults = 0, dropped_frames = 0;
  bool operator==(const SessionServoFigures&) const = default;
};
SessionServoFigures servo_figures(const ServoStats& stats, std::uint64_t dropped_frames);

struct SessionSummary {
  std::int64_t id = 0;
  std::string uuid;  // the same on every store it was copied to (schema 5 on)
  std::string trainee;
  std::string scenario_title;
  std::string scenario_sha256;
  std::string device;
  std::int64_t started_unix_ms = 0;
  std::optional<std::int64_t> ended_unix_ms;
  SessionStatus status = SessionStatus::recording;
  std::int64_t frame_count = 0;
  std::optional<SessionServoFigures> servo;  // set when the session ended normally
  std::optional<WorkspaceMapping> mapping;   // none for sessions recorded before schema 2
  // The left hand's device, its frames and, once ended, its servo figures (schema 7 on): none
  // for a one-handed session. `device`, `frame_count`, `servo` above are the right hand's.
  std::optional<LeftHandDevice> left_hand;
  std::int64_t left_frame_count = 0;
  std::optional<SessionServoFigures> left_servo;
};

// A gradable metric's value (gradable_metrics() in scenario.h names them and their units).
struct MetricValue {
  std::string name;
  double value = 0.0;
  bool operator==(const MetricValue&) const = default;
};

// An instructor's grade of a session.
struct SessionGrade {
  std::string instructor;
  std::int64_t graded_unix_ms = 0;
  std::optional<double> score_percent;  // the rubric's score when graded (none: no rubric)
  std::string grade;                    // e.g. "pass", "B+"
  std::string comment;
  bool operator==(const SessionGrade&) const = default;
};

// The tools a hand used over a session, from its tool_selected events ("hand" or an unknown name
// ends the tool before).
std::vector<ToolInterval> tool_intervals(std::span<const SessionEvent> events,
                                         Hand hand = Hand::right);
// A lesion_marked event's detail for a rest point, and the marks of a session's events (a detail
// that is not three finite numbers is skipped).
std::string mark_detail(const Eigen::Vector3d& rest_point_m);
std::vector<Eigen::Vector3d> lesion_marks(std::span<const SessionEvent> events);
// The metrics of the session's trace (trace_metrics.h), under their gradable names: the right
// hand's (the session's device) unprefixed; the left hand's device's with "left_" before them
// (but for task_time_s, which is the session's).
std::vector<MetricValue> trace_metric_values(const TraceMetrics& metrics);
std::vector<MetricValue> left_hand_metric_values(const TraceMetrics& metrics);

// Frames travel and are stored in chunks (one per commit): a documented, versioned byte layout
// (docs/session-storage.md), little-endian whatever the machine. Exact: doubles keep every bit.
// Layout 2 adds the stylus's orientation (issue 43); chunks of layout 1 still read (no
// orientation). A chunk is written in the newest layout.
inline constexpr int kFrameChunkLayout = 2;
std::vector<std::uint8_t> encode_frame_chunk(std::span<const ServoFrame> frames);
// Throws StorageError when the bytes are not a layout-1 or layout-2 chunk (wrong magic, size or
// count).
std::vector<ServoFrame> decode_frame_chunk(std::span<const std::uint8_t> bytes);

// The simulation's input log travels and is stored in chunks too (layout 1, "LSI1",
// docs/session-storage.md): one record per input, exact.
inline constexpr int kInputChunkLayout = 1;
std::vector<std::uint8_t> encode_input_chunk(std::span<const SimulationInput> inputs);
// Throws StorageError when the bytes are not a layout-1 input chunk, naming what is wrong.
std::vector<SimulationInput> decode_input_chunk(std::span<const std::uint8_t> bytes);

// A role's limit: what was asked is not the asker's to do (a trainee grading, a wrong password).
class AccessDenied : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Proof that an instructor logged in with their password: only a store makes one
// (SessionStore::log_in_instructor), and what only instructors may do takes one.
class Instructor {
 public:
  std::int64_t id() const { return id_; }
  const std::string& name() const { return name_; }

 private:
  friend class SessionStore;
  Instructor(std::int64_t id, std::string name) : id_(id), name_(std::move(name)) {}
  std::int64_t id_;
  std::string name_;
};

// Reading a long session's frames (ten minutes at 1 kHz are 600 000): frames read so far and in
// the session, after each chunk. Returning false stops the reading (ReadingCancelled).
using ReadingProgress = std::function<bool(std::size_t frames_read, std::size_t frames_total)>;
struct ReadingCancelled : std::runtime_error {
  ReadingCancelled() : std::runtime_error("reading the session was cancelled") {}
};

// Where sessions go. One writer: the recorder's thread calls the writing functions; a writer's
// appends become durable together at commit(). Every function may throw StorageError.
class SessionStore {
 public:
  virtual ~SessionStore() = default;

  // A new session, status recording, committed at once; returns its id.
  virtual std::int64_t begin_session(const SessionStart& start) = 0;
  // The session's next frames of a hand's device (in order, after those appended before) and
  // events. A left hand's frames need a session begun with a left-hand device.
  void append_frames(std::int64_t session, std::span<const ServoFrame> frames) {
    append_frames(session, Hand::right, frames);
  }
  virtual void append_frames(std::int64_t session, Hand hand,
                             std::span<const ServoFrame> frames) = 0;
  virtual void append_events(std::int64_t session, std::span<const SessionEvent> events) = 0;
  // The simulation's next inputs (in order), for a session begun with a ReplaySetup.
  virtual void append_inputs(std::int64_t session, std::span<const SimulationInput> inputs) = 0;
  virtual void commit() = 0;
  // Ends the session normally: status complete, end time and servo figures (the left hand's
  // device's too, in a two-handed session); commits.
  void end_session(std::int64_t session, std::int64_t ended_unix_ms,
                   const SessionServoFigures& servo) {
    end_session(session, ended_unix_ms, servo, std::nullopt);
  }
  virtual void end_session(std::int64_t session, std::int64_t ended_unix_ms,
                           const SessionServoFigures& servo,
                           const std::optional<SessionServoFigures>& left_servo) = 0;

  // The session's metrics, computed at its end (a name stored again replaces its value); commits.
  virtual void store_metrics(std::int64_t session, std::span<const MetricValue> metrics) = 0;

  // Instructor accounts: a name and a password kept as an Argon2id hash (password_hash.h).
  // The first account may be added by anyone (setting up a new workstation); later ones only by
  // an instructor who logged in (AccessDenied otherwise). A name taken, or a password that breaks
  // the rule (check_new_password), is refused naming why. Commits.
  virtual Instructor add_instructor_account(std::string_view name, std::string_view password,
                                            const Instructor* added_by) = 0;
  virtual bool has_instructor_accounts() = 0;
  // The instructor, when the name has an account and the password is its own; nullopt for a
  // wrong name or password alike (after the same work, so the answer's time tells nothing).
  virtual std::optional<Instructor> log_in_instructor(std::string_view name,
                                                      std::string_view password) = 0;

  // The grade and comment of the instructor who logged in (grade.instructor is theirs; the
  // Instructor must be of this store's accounts, AccessDenied otherwise); commits. A session may
  // be graded more than once: each grade is kept.
  virtual void store_grade(const Instructor& by, std::int64_t session,
                           const SessionGrade& grade) = 0;
  virtual std::vector<SessionGrade> grades(std::int64_t session) = 0;  // oldest first

  virtual std::vector<SessionSummary> sessions() = 0;
  // Only the sessions of the trainee of that name: what a trainee's own history shows.
  virtual std::vector<SessionSummary> sessions_of_trainee(std::string_view trainee) = 0;
  virtual std::vector<MetricValue> metrics(std::int64_t session) = 0;  // by name
  // A hand's frames (the right hand's: the session's device).
  std::vector<ServoFrame> frames(std::int64_t session, Hand hand = Hand::right) {
    return frames(session, hand, {});
  }
  std::vector<ServoFrame> frames(std::int64_t session, const ReadingProgress& progress) {
    return frames(session, Hand::right, progress);
  }
  virtual std::vector<ServoFrame> frames(std::int64_t session, Hand hand,
                                         const ReadingProgress& progress) = 0;
  virtual std::vector<SessionEvent> events(std::int64_t session) = 0;
  // What a replay needs: how the scene was built (none: not recorded) and the input log.
  virtual std::optional<ReplaySetup> replay_setup(std::int64_t session) = 0;
  virtual std::vector<SimulationInput> inputs(std::int64_t session) = 0;
  // The exact scenario text the session ran.
  virtual std::string scenario_text(std::int64_t session) = 0;

 protected:
  // For a store that has checked the password.
  static Instructor vouch_for(std::int64_t id, std::string name) {
    return Instructor(id, std::move(name));
  }
};

}  // namespace liversim
