#pragma once
// The embedded session store: one SQLite file (WAL, prepared statements, bound parameters only).
// Schema and frame layout: docs/session-storage.md. A separate library from the engine
// (liversim_storage) so that the engine itself needs no database.

#include "liversim/sessions/session_store.h"
#include "liversim/storage/password_hash.h"
#include "liversim/storage/session_transfer.h"

#include <filesystem>
#include <memory>

struct sqlite3;

namespace liversim {

class SqliteSessionStore final : public SessionStore {
 public:
  enum class Access { read_write, read_only };

  // The schema version this build writes; files at older versions are migrated on opening.
  static constexpr int kSchemaVersion = 7;

  // Opens the file, creating it (read_write) if it does not exist. Throws StorageError naming the
  // file when it cannot be opened, is not a LiverSim database, is damaged, is read-only while
  // read_write was asked for, or was written by a newer version. Opened for writing, sessions
  // left recording by a writer that was killed are marked incomplete.
  explicit SqliteSessionStore(const std::filesystem::path& file,
                              Access access = Access::read_write);
  ~SqliteSessionStore() override;
  SqliteSessionStore(const SqliteSessionStore&) = delete;
  SqliteSessionStore& operator=(const SqliteSessionStore&) = delete;

  const std::filesystem::path& file() const { return file_; }
  int schema_version();
  // PRAGMA integrity_check: "ok", or what SQLite found.
  std::string integrity_check();
  // Caps the file at this many pages (SQLite's max_page_count): what a full disk does.
  void limit_pages_for_testing(std::int64_t pages);

  std::int64_t begin_session(const SessionStart& start) override;
  using SessionStore::append_frames;
  void append_frames(std::int64_t session, Hand hand, std::span<const ServoFrame> frames) override;
  void append_events(std::int64_t session, std::span<const SessionEvent> events) override;
  void append_inputs(std::int64_t session, std::span<const SimulationInput> inputs) override;
  void commit() override;
  using SessionStore::end_session;
  void end_session(std::int64_t session, std::int64_t ended_unix_ms,
                   const SessionServoFigures& servo,
                   const std::optional<SessionServoFigures>& left_servo) override;

  void store_metrics(std::int64_t session, std::span<const MetricValue> metrics) override;

  Instructor add_instructor_account(std::string_view name, std::string_view password,
                                    const Instructor* added_by) override;
  bool has_instructor_accounts() override;
  std::optional<Instructor> log_in_instructor(std::string_view name,
                                              std::string_view password) override;
  // How costly new password hashes are (tests make them cheap; logins check any cost).
  void set_password_cost_for_testing(const PasswordHashCost& cost) { password_cost_ = cost; }

  void store_grade(const Instructor& by, std::int64_t session, const SessionGrade& grade) override;
  std::vector<SessionGrade> grades(std::int64_t session) override;
  std::vector<SessionSummary> sessions() override;
  std::vector<SessionSummary> sessions_of_trainee(std::string_view trainee) override;
  std::vector<MetricValue> metrics(std::int64_t session) override;
  using SessionStore::frames;
  std::vector<ServoFrame> frames(std::int64_t session, Hand hand,
                                 const ReadingProgress& progress) override;
  std::vector<SessionEvent> events(std::int64_t session) override;
  std::string scenario_text(std::int64_t session) override;
  std::optional<ReplaySetup> replay_setup(std::int64_t session) override;
  std::vector<SimulationInput> inputs(std::int64_t session) override;

  // The training centre (session_upload.h). `server` names the server (server_name()).
  // The sessions that ended (complete or incomplete) and are not yet on that server, oldest first.
  // A complete session waits for its metrics (computed after its end, on a worker), or, should
  // they never come, until kMetricsWaitMs after its end: an upload is never amended.
  std::vector<std::int64_t> sessions_to_upload(std::string_view server);
  static constexpr std::int64_t kMetricsWaitMs = 120'000;
  // The session as it is uploaded; its chunk sources read this store while they are called.
  SessionTransfer transfer_of(std::int64_t session);
  // The server has the session / an upload of it failed (the attempt counted, the problem kept).
  void mark_uploaded(std::int64_t session, std::string_view server, std::int64_t unix_ms);
  void note_upload_problem(std::int64_t session, std::string_view server, std::string_view problem);
  struct UploadState {
    std::optional<std::int64_t> uploaded_unix_ms;
    std::int64_t attempts = 0;
    std::string last_problem;
  };
  UploadState upload_state(std::int64_t session, std::string_view server);
  // The UUIDs of the sessions that are on that server.
  std::vector<std::string> uploaded_session_uuids(std::string_view server);
  // Grades from the server, of sessions held here: each added once (by its UUID); those of
  // sessions not held here are skipped. Returns how many were new. Commits.
  int store_shared_grades(std::span<const SharedGrade> grades);

 private:
  class Statement;
  void execute(const char* sql, const char* doing);
  void begin_if_needed();
  // Throws (StorageProblem::deleted) when the file opened is no longer at its path.
  void check_file_is_still_there();
  // An error about this file: "sessions database FILE: what".
  StorageError error(const std::string& what, StorageProblem problem = StorageProblem::other) const;
  // What SQLite reported last: its extended result code, its message and the errno of the system
  // call behind it (a write refused by a read-only file system is an I/O error with EROFS; a
  // full disk, ENOSPC).
  struct Failure {
    int code = 0;
    std::string message;
    int system_errno = 0;
  };
  Failure last_failure() const;
  [[noreturn]] void fail(const std::string& doing) const { fail(doing, last_failure()); }
  [[noreturn]] void fail(const std::string& doing, const Failure& failure) const;
  Statement& prepared(int which, const char* sql);
  // The session's chunks of `items` ("frames", "inputs") from `chunks` (first item, layout, data,
  // in order), decoded and joined; a gap or a layout this version cannot read is named. With
  // `progress`, `total` is how many items there are.
  template <typename Item, typename Decode>
  std::vector<Item> chunks_of(std::int64_t session, Statement& chunks, const std::string& items,
                              int layout, Decode decode, const ReadingProgress& progress = {},
                              std::size_t total = 0);
  // The id of the person of that name and role ("trainee", "instructor"), added if new.
  std::int64_t person(std::string_view name, std::string_view role);
  // The instructor account of that name: its person id and password hash.
  std::optional<std::pair<std::int64_t, std::string>> account_of(std::string_view name);
  // AccessDenied unless the instructor has an account here.
  void require_account(const Instructor& instructor);
  // The sessions, all (no trainee) or one trainee's.
  std::vector<SessionSummary> list_sessions(std::optional<std::string_view> trainee);

  std::filesystem::path file_;
  sqlite3* db_ = nullptr;
  bool in_transaction_ = false;
  std::vector<std::unique_ptr<Statement>> statements_;
  PasswordHashCost password_cost_ = kInteractivePasswordCost;
  // The file opened (device, inode): a commit refuses to write to a file deleted or replaced.
  std::uint64_t file_device_ = 0;
  std::uint64_t file_inode_ = 0;
  bool file_identity_known_ = false;
  // While this connection records a session it holds FILE-recording.lock shared (flock, so
  // per open file, released by the kernel when the process dies): an opening for writing closes
  // the sessions left recording only when it can lock that file exclusively, so a review window
  // or the training centre's link, opened while the workstation records, does not.
  int recording_lock_fd_ = -1;
  int sessions_recording_ = 0;
  std::filesystem::path recording_lock_file() const;
  void hold_recording_lock();
  void release_recording_lock();
};

}  // namespace liversim
