#include "liversim/storage/sqlite_session_store.h"

#include "liversim/engine/integrator.h"
#include "liversim/storage/session_transfer.h"
#include "liversim/storage/sha256.h"
#include "stored_rows.h"

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

namespace liversim {

namespace {

// Version 1. Each later version adds its step to kMigrations (and a test that opens a file of
// every earlier version: tests/data/storage/sessions-vN.sqlite, written by that version).
constexpr const char* kSchemaV1 = R"sql(
CREATE TABLE people (
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL,
  role TEXT NOT NULL CHECK (role IN ('trainee', 'instructor')),
  UNIQUE (name, role)
);
CREATE TABLE scenarios (
  id INTEGER PRIMARY KEY,
  sha256 TEXT NOT NULL UNIQUE,
  title TEXT NOT NULL,
  content TEXT NOT NULL
);
CREATE TABLE sessions (
  id INTEGER PRIMARY KEY,
  trainee_id INTEGER NOT NULL REFERENCES people (id),
  scenario_id INTEGER NOT NULL REFERENCES scenarios (id),
  device TEXT NOT NULL,
  started_unix_ms INTEGER NOT NULL,
  ended_unix_ms INTEGER,
  status TEXT NOT NULL CHECK (status IN ('recording', 'complete', 'incomplete')),
  frame_count INTEGER NOT NULL DEFAULT 0,
  servo_ticks INTEGER,
  servo_rate_hz REAL,
  servo_period_p50_ms REAL,
  servo_period_p99_ms REAL,
  servo_period_max_ms REAL,
  missed_deadlines INTEGER,
  force_clamps INTEGER,
  stiffness_clamps INTEGER,
  rate_limited INTEGER,
  watchdog_trips INTEGER,
  device_faults INTEGER,
  dropped_frames INTEGER
);
CREATE TABLE frame_chunks (
  session_id INTEGER NOT NULL REFERENCES sessions (id),
  first_frame INTEGER NOT NULL,
  frame_count INTEGER NOT NULL,
  first_time_s REAL NOT NULL,
  last_time_s REAL NOT NULL,
  layout INTEGER NOT NULL,
  data BLOB NOT NULL,
  PRIMARY KEY (session_id, first_frame)
) WITHOUT ROWID;
CREATE TABLE events (
  id INTEGER PRIMARY KEY,
  session_id INTEGER NOT NULL REFERENCES sessions (id),
  time_s REAL NOT NULL,
  kind TEXT NOT NULL,
  detail TEXT NOT NULL
);
CREATE INDEX events_by_session ON events (session_id, time_s);
CREATE TABLE metrics (
  session_id INTEGER NOT NULL REFERENCES sessions (id),
  name TEXT NOT NULL,
  value REAL NOT NULL,
  PRIMARY KEY (session_id, name)
);
CREATE TABLE grades (
  id INTEGER PRIMARY KEY,
  session_id INTEGER NOT NULL REFERENCES sessions (id),
  instructor_id INTEGER NOT NULL REFERENCES people (id),
  graded_unix_ms INTEGER NOT NULL,
  score REAL,
  grade TEXT NOT NULL,
  comment TEXT NOT NULL
);
)sql";

// kMigrations[v] takes a file from version v to v + 1 (version 0: a new, empty file).
// Version 2: the session's workspace mapping (device → scene), so that its tissue forces and a
// replay can be recovered; null for sessions recorded before.
constexpr const char* kSchemaV2 = R"sql(
ALTER TABLE sessions ADD COLUMN mapping_scale REAL;
ALTER TABLE sessions ADD COLUMN mapping_rotation_w REAL;
ALTER TABLE sessions ADD COLUMN mapping_rotation_x REAL;
ALTER TABLE sessions ADD COLUMN mapping_rotation_y REAL;
ALTER TABLE sessions ADD COLUMN mapping_rotation_z REAL;
ALTER TABLE sessions ADD COLUMN mapping_offset_x_m REAL;
ALTER TABLE sessions ADD COLUMN mapping_offset_y_m REAL;
ALTER TABLE sessions ADD COLUMN mapping_offset_z_m REAL;
)sql";

// Version 3: the simulation's input log, so that a session can be replayed in the viewport
// (docs/session-storage.md, "Replay"): how its scene was built and its inputs in chunks.
constexpr const char* kSchemaV3 = R"sql(
ALTER TABLE sessions ADD COLUMN input_count INTEGER NOT NULL DEFAULT 0;
CREATE TABLE session_replays (
  session_id INTEGER PRIMARY KEY REFERENCES sessions (id),
  built_in_liver_tets INTEGER,
  scenario_folder TEXT NOT NULL,
  integrator TEXT NOT NULL,
  step_s REAL NOT NULL,
  tolerance_m REAL NOT NULL,
  newton_tolerance_m REAL NOT NULL,
  max_newton_iterations INTEGER NOT NULL
);
CREATE TABLE input_chunks (
  session_id INTEGER NOT NULL REFERENCES sessions (id),
  first_input INTEGER NOT NULL,
  input_count INTEGER NOT NULL,
  layout INTEGER NOT NULL,
  data BLOB NOT NULL,
  PRIMARY KEY (session_id, first_input)
) WITHOUT ROWID;
)sql";

// Version 4: instructor accounts. The password is kept only as an Argon2id hash
// (password_hash.h); grading needs an instructor who logged in with it.
constexpr const char* kSchemaV4 = R"sql(
CREATE TABLE instructor_accounts (
  person_id INTEGER PRIMARY KEY REFERENCES people (id),
  password_hash TEXT NOT NULL,
  created_unix_ms INTEGER NOT NULL
);
)sql";

// A random version-4 UUID in SQL, for the rows that were there before version 5.
#define LIVERSIM_SQL_UUID                                                                    \
  "lower(hex(randomblob(4))) || '-' || lower(hex(randomblob(2))) || '-4' || "                \
  "substr(lower(hex(randomblob(2))), 2) || '-' || substr('89ab', 1 + abs(random()) % 4, 1) " \
  "|| substr(lower(hex(randomblob(2))), 2) || '-' || lower(hex(randomblob(6)))"

// Version 5: the training centre (docs/training-centre.md). Sessions and grades get UUIDs, so
// that an upload done twice and a grade pulled twice are stored once; the uploads done (and
// tried) to each server.
constexpr const char* kSchemaV5 =
    "ALTER TABLE sessions ADD COLUMN uuid TEXT;"
    "UPDATE sessions SET uuid = " LIVERSIM_SQL_UUID
    ";"
    "CREATE UNIQUE INDEX sessions_by_uuid ON sessions (uuid);"
    "ALTER TABLE grades ADD COLUMN uuid TEXT;"
    "UPDATE grades SET uuid = " LIVERSIM_SQL_UUID
    ";"
    "CREATE UNIQUE INDEX grades_by_uuid ON grades (uuid);"
    "CREATE TABLE session_uploads ("
    "  session_id INTEGER NOT NULL REFERENCES sessions (id),"
    "  server TEXT NOT NULL,"
    "  uploaded_unix_ms INTEGER,"
    "  attempts INTEGER NOT NULL DEFAULT 0,"
    "  last_problem TEXT,"
    "  PRIMARY KEY (session_id, server)"
    ") WITHOUT ROWID;";
#undef LIVERSIM_SQL_UUID

// Version 6: the real-time loop's step a session was recorded with (a cycle of its input log is a
// count of them); NULL for the sessions before, which replay with the model's stable step.
constexpr const char* kSchemaV6 = "ALTER TABLE session_replays ADD COLUMN loop_step_s REAL;";

// Version 7: the left hand (issue 43). A session of two devices keeps the left one's name,
// mapping, frame count and servo figures beside the right one's, and its frames in chunks of
// their own; each event names the hand it is of (those before are the right hand's, the only one
// then).
constexpr const char* kSchemaV7 = R"sql(
ALTER TABLE sessions ADD COLUMN left_device TEXT;
ALTER TABLE sessions ADD COLUMN left_frame_count INTEGER NOT NULL DEFAULT 0;
ALTER TABLE sessions ADD COLUMN left_mapping_scale REAL;
ALTER TABLE sessions ADD COLUMN left_mapping_rotation_w REAL;
ALTER TABLE sessions ADD COLUMN left_mapping_rotation_x REAL;
ALTER TABLE sessions ADD COLUMN left_mapping_rotation_y REAL;
ALTER TABLE sessions ADD COLUMN left_mapping_rotation_z REAL;
ALTER TABLE sessions ADD COLUMN left_mapping_offset_x_m REAL;
ALTER TABLE sessions ADD COLUMN left_mapping_offset_y_m REAL;
ALTER TABLE sessions ADD COLUMN left_mapping_offset_z_m REAL;
ALTER TABLE sessions ADD COLUMN left_servo_ticks INTEGER;
ALTER TABLE sessions ADD COLUMN left_servo_rate_hz REAL;
ALTER TABLE sessions ADD COLUMN left_servo_period_p50_ms REAL;
ALTER TABLE sessions ADD COLUMN left_servo_period_p99_ms REAL;
ALTER TABLE sessions ADD COLUMN left_servo_period_max_ms REAL;
ALTER TABLE sessions ADD COLUMN left_missed_deadlines INTEGER;
ALTER TABLE sessions ADD COLUMN left_force_clamps INTEGER;
ALTER TABLE sessions ADD COLUMN left_stiffness_clamps INTEGER;
ALTER TABLE sessions ADD COLUMN left_rate_limited INTEGER;
ALTER TABLE sessions ADD COLUMN left_watchdog_trips INTEGER;
ALTER TABLE sessions ADD COLUMN left_device_faults INTEGER;
ALTER TABLE sessions ADD COLUMN left_dropped_frames INTEGER;
CREATE TABLE left_hand_frame_chunks (
  session_id INTEGER NOT NULL REFERENCES sessions (id),
  first_frame INTEGER NOT NULL,
  frame_count INTEGER NOT NULL,
  first_time_s REAL NOT NULL,
  last_time_s REAL NOT NULL,
  layout INTEGER NOT NULL,
  data BLOB NOT NULL,
  PRIMARY KEY (session_id, first_frame)
) WITHOUT ROWID;
ALTER TABLE events ADD COLUMN hand TEXT NOT NULL DEFAULT 'right' CHECK (hand IN ('right', 'left'));
)sql";

constexpr std::array<const char*, 7> kMigrations = {kSchemaV1, kSchemaV2, kSchemaV3, kSchemaV4,
                                                    kSchemaV5, kSchemaV6, kSchemaV7};
static_assert(kMigrations.size() == SqliteSessionStore::kSchemaVersion);

enum StatementId {
  kFindPerson,
  kAddPerson,
  kFindScenario,
  kAddScenario,
  kAddSession,
  kFrameCount,
  kAddChunk,
  kCountFrames,
  kHasLeftHand,
  kLeftFrameCount,
  kAddLeftChunk,
  kCountLeftFrames,
  kLeftChunks,
  kLeftChunkFrameSum,
  kAddEvent,
  kEndSession,
  kSessions,
  kChunks,
  kChunkFrameSum,
  kEvents,
  kScenarioText,
  kStoreMetric,
  kMetrics,
  kStoreGrade,
  kAccountCount,
  kFindAccount,
  kAddAccount,
  kCheckGrader,
  kGrades,
  kAddReplay,
  kInputCount,
  kAddInputChunk,
  kCountInputs,
  kReplay,
  kInputChunks,
  kStatementCount
};

}  // namespace

// A prepared statement, reset after each use.
class SqliteSessionStore::Statement {
 public:
  Statement(SqliteSessionStore& store, const char* sql) : store_(store) {
    if (sqlite3_prepare_v2(store.db_, sql, -1, &statement_, nullptr) != SQLITE_OK)
      store.fail("preparing a query");
  }
  ~Statement() { sqlite3_finalize(statement_); }
  Statement& bind(int index, std::int64_t value) {
    check(sqlite3_bind_int64(statement_, index, value));
    return *this;
  }
  Statement& bind(int index, double value) {
    check(sqlite3_bind_double(statement_, index, value));
    return *this;
  }
  Statement& bind(int index, std::string_view text) {
    check(sqlite3_bind_text(statement_, index, text.data(), static_cast<int>(text.size()),
                            SQLITE_TRANSIENT));
    return *this;
  }
  Statement& bind_null(int index) {
    check(sqlite3_bind_null(statement_, index));
    return *this;
  }
  Statement& bind(int index, std::span<const std::uint8_t> bytes) {
    check(sqlite3_bind_blob(statement_, index, bytes.data(), static_cast<int>(bytes.size()),
                            SQLITE_TRANSIENT));
    return *this;
  }
  // True while there is a row; throws on an error.
  bool step(const char* doing) {
    const int result = sqlite3_step(statement_);
    if (result == SQLITE_ROW) return true;
    if (result == SQLITE_DONE) return false;
    sqlite3_reset(statement_);  // keeps the error for fail() to read
    store_.fail(doing);
  }
  // Column 0 of the one row it gives; an error when it gives none.
  std::int64_t single_integer(const char* doing) {
    if (!step(doing)) {
      reset();
      throw store_.error(std::string(doing) + " failed: no such row");
    }
    const std::int64_t value = integer(0);
    reset();
    return value;
  }
  void run(const char* doing) {
    while (step(doing)) {
    }
    reset();
  }
  void reset() {
    sqlite3_reset(statement_);
    sqlite3_clear_bindings(statement_);
  }
  std::int64_t integer(int column) const { return sqlite3_column_int64(statement_, column); }
  double real(int column) const { return sqlite3_column_double(statement_, column); }
  bool is_null(int column) const { return sqlite3_column_type(statement_, column) == SQLITE_NULL; }
  std::string text(int column) const {
    const auto* data = sqlite3_column_text(statement_, column);
    return data ? std::string(reinterpret_cast<const char*>(data),
                              static_cast<std::size_t>(sqlite3_column_bytes(statement_, column)))
                : std::string();
  }
  std::span<const std::uint8_t> blob(int column) const {
    const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(statement_, column));
    return {data, static_cast<std::size_t>(sqlite3_column_bytes(statement_, column))};
  }

 private:
  void check(int result) {
    if (result != SQLITE_OK) store_.fail("binding a query parameter");
  }
  SqliteSessionStore& store_;
  sqlite3_stmt* statement_ = nullptr;
};

SqliteSessionStore::SqliteSessionStore(const std::filesystem::path& file, Access access)
    : file_(file) {
  const int flags = access == Access::read_write ? SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE
                                                 : SQLITE_OPEN_READONLY;
  if (sqlite3_open_v2(file.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
    const std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw error("cannot open it (" + message + ")", StorageProblem::unreachable);
  }
  statements_.resize(kStatementCount);
  if (struct stat opened{}; stat(file.c_str(), &opened) == 0) {
    file_device_ = opened.st_dev;
    file_inode_ = opened.st_ino;
    file_identity_known_ = true;
  }
  try {
    sqlite3_extended_result_codes(db_, 1);
    sqlite3_busy_timeout(db_, 2000);
    // Reading the version reads the header: a file that is no database fails here.
    const int version = schema_version();
    // LiverSim writes 1, 2, ...: another program's number would index no migration.
    if (version < 0)
      throw error("not a LiverSim sessions database (its schema version is " +
                      std::to_string(version) + ", below 0)",
                  StorageProblem::not_a_database);
    if (version > kSchemaVersion)
      throw error("written by a newer LiverSim (schema version " + std::to_string(version) +
                      "; this one reads up to " + std::to_string(kSchemaVersion) + ")",
                  StorageProblem::newer_version);
    if (access == Access::read_write && sqlite3_db_readonly(db_, "main") == 1)
      throw error("cannot write to it (the file is read-only)", StorageProblem::read_only);
    if (version == 0) {
      if (Statement(*this, "SELECT count(*) FROM sqlite_master").single_integer("reading it") != 0)
        throw error("not a LiverSim sessions database (it holds other tables)",
                    StorageProblem::not_a_database);
    }
    if (access == Access::read_write) {
      execute("PRAGMA journal_mode = WAL", "opening it for writing");
      // With WAL: durable against a killed process (not against a power cut).
      execute("PRAGMA synchronous = NORMAL", "opening it for writing");
      execute("PRAGMA foreign_keys = ON", "opening it for writing");
      for (int v = version; v < kSchemaVersion; ++v) {
        const std::string doing = "migrating it to schema version " + std::to_string(v + 1);
        execute("BEGIN IMMEDIATE", doing.c_str());
        execute(kMigrations[static_cast<std::size_t>(v)], doing.c_str());
        execute(("PRAGMA user_version = " + std::to_string(v + 1)).c_str(), doing.c_str());
        execute("COMMIT", doing.c_str());
      }
      // A writer killed mid-session left it recording: it is over, not lost. Not while another
      // connection records (it holds the recording lock): its session goes on.
      const int lock = ::open(recording_lock_file().c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
      if (lock < 0 || flock(lock, LOCK_EX | LOCK_NB) == 0)
        execute("UPDATE sessions SET status = 'incomplete' WHERE status = 'recording'",
                "closing sessions left recording");
      if (lock >= 0) ::close(lock);  // and the lock with it
    } else if (version < kSchemaVersion) {
      throw error("schema version " + std::to_string(version) +
                  " needs migrating; open it for writing once");
    }
  } catch (...) {
    statements_.clear();
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  }
}

std::filesystem::path SqliteSessionStore::recording_lock_file() const {
  return file_.string() + "-recording.lock";
}

void SqliteSessionStore::hold_recording_lock() {
  if (recording_lock_fd_ >= 0) return;
  // Without the lock file (a folder turned read-only) the session is recorded all the same; an
  // opening meanwhile may then take it for one left recording.
  recording_lock_fd_ = ::open(recording_lock_file().c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (recording_lock_fd_ >= 0 && flock(recording_lock_fd_, LOCK_SH) != 0) release_recording_lock();
}

void SqliteSessionStore::release_recording_lock() {
  if (recording_lock_fd_ >= 0) ::close(recording_lock_fd_);
  recording_lock_fd_ = -1;
}

SqliteSessionStore::~SqliteSessionStore() {
  release_recording_lock();
  if (in_transaction_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  statements_.clear();
  sqlite3_close(db_);
}

StorageError SqliteSessionStore::error(const std::string& what, StorageProblem problem) const {
  return StorageError("sessions database " + file_.string() + ": " + what, problem);
}

namespace {

// The errno of the last failed system call on a file of the connection, which SQLite keeps with
// the file: `file_pointer` SQLITE_FCNTL_JOURNAL_POINTER for its WAL (a commit writes there),
// SQLITE_FCNTL_FILE_POINTER for the database. sqlite3_system_errno does not always have it
// (SQLite 3.40 leaves it 0 when COMMIT fails writing the WAL).
int file_errno(sqlite3* db, int file_pointer) {
  sqlite3_file* file = nullptr;
  int error = 0;
  if (sqlite3_file_control(db, "main", file_pointer, &file) != SQLITE_OK || file == nullptr ||
      file->pMethods == nullptr ||
      file->pMethods->xFileControl(file, SQLITE_FCNTL_LAST_ERRNO, &error) != SQLITE_OK)
    return 0;
  return error;
}

}  // namespace

SqliteSessionStore::Failure SqliteSessionStore::last_failure() const {
  Failure failure;
  failure.code = sqlite3_extended_errcode(db_);
  failure.message = sqlite3_errmsg(db_);
  failure.system_errno = sqlite3_system_errno(db_);
  for (const int which : {SQLITE_FCNTL_JOURNAL_POINTER, SQLITE_FCNTL_FILE_POINTER}) {
    if (const int error = file_errno(db_, which);
        error == EROFS || error == ENOSPC || error == EDQUOT) {
      failure.system_errno = error;
      break;
    }
  }
  return failure;
}

void SqliteSessionStore::fail(const std::string& doing, const Failure& failure) const {
  const int primary = failure.code & 0xff;
  int kind = primary;
  std::string cause = failure.message;
  // A write the system refused: SQLite calls it an I/O error (or read-only, or cannot open); the
  // errno says which trouble it is, and is named before SQLite's message.
  constexpr int kReadOnlyFileSystem = -1;
  const int system_errno = failure.system_errno;
  if ((primary == SQLITE_IOERR || primary == SQLITE_READONLY || primary == SQLITE_CANTOPEN) &&
      (system_errno == EROFS || system_errno == ENOSPC || system_errno == EDQUOT)) {
    kind = system_errno == EROFS ? kReadOnlyFileSystem : SQLITE_FULL;
    cause = std::string(std::strerror(system_errno)) + "; " + cause;
  }
  std::string what = cause;
  StorageProblem problem = StorageProblem::other;
  switch (kind) {
    case kReadOnlyFileSystem:
      what = "the file is read-only: its file system was made read-only (" + cause + ")";
      problem = StorageProblem::read_only;
      break;
    case SQLITE_FULL:
      what = "the disk or the database is full (" + cause + ")";
      problem = StorageProblem::disk_full;
      break;
    case SQLITE_CORRUPT:
      what = "the file is damaged (" + cause + ")";
      problem = StorageProblem::damaged;
      break;
    case SQLITE_NOTADB:
      what = "not a database file (" + cause + ")";
      problem = StorageProblem::not_a_database;
      break;
    case SQLITE_READONLY:
      what = "the file is read-only (" + cause + ")";
      problem = StorageProblem::read_only;
      break;
    case SQLITE_IOERR:
      what = "the file could not be read or written (" + cause + ")";
      problem = StorageProblem::unreachable;
      break;
    case SQLITE_CANTOPEN:
      problem = StorageProblem::unreachable;
      break;
    default:
      break;
  }
  throw error(doing + " failed: " + what, problem);
}

void SqliteSessionStore::execute(const char* sql, const char* doing) {
  if (sqlite3_exec(db_, sql, nullptr, nullptr, nullptr) != SQLITE_OK) fail(doing);
}

SqliteSessionStore::Statement& SqliteSessionStore::prepared(int which, const char* sql) {
  auto& slot = statements_[static_cast<std::size_t>(which)];
  if (!slot) slot = std::make_unique<Statement>(*this, sql);
  return *slot;
}

int SqliteSessionStore::schema_version() {
  return static_cast<int>(Statement(*this, "PRAGMA user_version").single_integer("reading it"));
}

std::string SqliteSessionStore::integrity_check() {
  Statement check(*this, "PRAGMA integrity_check");
  std::string result;
  while (check.step("checking integrity")) result += (result.empty() ? "" : "; ") + check.text(0);
  return result;
}

void SqliteSessionStore::limit_pages_for_testing(std::int64_t pages) {
  execute(("PRAGMA max_page_count = " + std::to_string(pages)).c_str(), "capping its size");
}

void SqliteSessionStore::begin_if_needed() {
  if (in_transaction_) return;
  check_file_is_still_there();
  // IMMEDIATE: the write lock now, waiting (busy timeout) for another connection's write to end.
  // A deferred transaction that read first could not take it once another connection had
  // committed (SQLITE_BUSY_SNAPSHOT, at once): the training centre's link writing its notes
  // made the recorder's next append fail.
  if (sqlite3_exec(db_, "BEGIN IMMEDIATE", nullptr, nullptr, nullptr) != SQLITE_OK)
    fail("starting a transaction");
  in_transaction_ = true;
}

void SqliteSessionStore::check_file_is_still_there() {
  // A deleted file stays open and takes every write, which is then lost with it; a file put in
  // its place shares its journal's name, so the connection would read another database's.
  struct stat now {};
  if (!file_identity_known_ ||
      (stat(file_.c_str(), &now) == 0 && now.st_dev == file_device_ && now.st_ino == file_inode_))
    return;
  if (in_transaction_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  in_transaction_ = false;
  throw error(
      "the file was deleted or replaced while it was in use; what is recorded now cannot be "
      "saved in it",
      StorageProblem::deleted);
}

void SqliteSessionStore::commit() {
  if (!in_transaction_) return;
  check_file_is_still_there();
  if (sqlite3_exec(db_, "COMMIT", nullptr, nullptr, nullptr) != SQLITE_OK) {
    // Read before the rollback, which reports its own result (SQLite may have rolled back
    // already: "no transaction is active").
    const Failure failure = last_failure();
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    in_transaction_ = false;
    fail("committing", failure);
  }
  in_transaction_ = false;
}

std::int64_t SqliteSessionStore::person(std::string_view name, std::string_view role) {
  const std::string doing = "adding the " + std::string(role);
  prepared(kAddPerson, "INSERT OR IGNORE INTO people (name, role) VALUES (?1, ?2)")
      .bind(1, name)
      .bind(2, role)
      .run(doing.c_str());
  const std::string looking = "looking up the " + std::string(role);
  return prepared(kFindPerson, "SELECT id FROM people WHERE name = ?1 AND role = ?2")
      .bind(1, name)
      .bind(2, role)
      .single_integer(looking.c_str());
}

std::int64_t SqliteSessionStore::begin_session(const SessionStart& start) {
  hold_recording_lock();  // before the row: no opening may close it
  ++sessions_recording_;
  begin_if_needed();
  // Added if new (a name per role and a text's hash are unique), then looked up either way.
  const std::int64_t trainee = person(start.trainee, "trainee");
  const std::string hash = sha256_hex(start.scenario_text);
  prepared(kAddScenario,
           "INSERT OR IGNORE INTO scenarios (sha256, title, content) VALUES (?1, ?2, ?3)")
      .bind(1, std::string_view(hash))
      .bind(2, std::string_view(start.scenario_title))
      .bind(3, std::string_view(start.scenario_text))
      .run("storing the scenario");
  const std::int64_t scenario =
      prepared(kFindScenario, "SELECT id FROM scenarios WHERE sha256 = ?1")
          .bind(1, std::string_view(hash))
          .single_integer("looking up the scenario");
  static const std::string insert =
      "INSERT INTO sessions (trainee_id, scenario_id, device, started_unix_ms, status, " +
      std::string(stored_rows::kMappingColumns) + ", uuid, left_device, " +
      stored_rows::kLeftMappingColumns +
      ") VALUES (?1, ?2, ?3, ?4, 'recording', ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, "
      "?16, ?17, ?18, ?19, ?20, ?21, ?22)";
  Statement& add = prepared(kAddSession, insert.c_str());
  add.bind(1, trainee)
      .bind(2, scenario)
      .bind(3, std::string_view(start.device))
      .bind(4, start.started_unix_ms)
      .bind(13, std::string_view(new_uuid()));
  // A mapping's eight columns from parameter `first` on, null without one.
  const auto bind_mapping = [&](int first, const std::optional<WorkspaceMapping>& mapping) {
    for (int k = 0; k < 8; ++k)
      if (mapping)
        add.bind(first + k, stored_rows::mapping_values(*mapping)[static_cast<std::size_t>(k)]);
      else
        add.bind_null(first + k);
  };
  bind_mapping(5, start.mapping);
  std::optional<WorkspaceMapping> left_mapping;
  if (const auto& left = start.left_hand) {
    add.bind(14, std::string_view(left->device));
    left_mapping = left->mapping;
  } else {
    add.bind_null(14);
  }
  bind_mapping(15, left_mapping);
  add.run("adding the session");
  const std::int64_t session = sqlite3_last_insert_rowid(db_);
  if (const auto& replay = start.replay) {
    Statement& add_replay =
        prepared(kAddReplay,
                 "INSERT INTO session_replays (session_id, built_in_liver_tets, scenario_folder, "
                 "integrator, step_s, tolerance_m, newton_tolerance_m, max_newton_iterations, "
                 "loop_step_s) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)");
    add_replay.bind(1, session);
    if (replay->built_in_liver_tets)
      add_replay.bind(2, std::int64_t{*replay->built_in_liver_tets});
    else
      add_replay.bind_null(2);
    if (replay->loop_step_s)
      add_replay.bind(9, *replay->loop_step_s);
    else
      add_replay.bind_null(9);
    const IntegratorSettings& i = replay->integrator;
    add_replay.bind(3, std::string_view(replay->scenario_folder))
        .bind(4, integrator_name(i.kind))
        .bind(5, i.step_s)
        .bind(6, i.tolerance_m)
        .bind(7, i.newton_tolerance_m)
        .bind(8, std::int64_t{i.max_newton_iterations})
        .run("storing how to replay the session");
  }
  commit();
  return session;
}

void SqliteSessionStore::append_frames(std::int64_t session, Hand hand,
                                       std::span<const ServoFrame> frames) {
  if (frames.empty()) return;
  begin_if_needed();
  const bool left = hand == Hand::left;
  const std::string looking = "looking up session " + std::to_string(session);
  // The left hand's count, or -1 for a session begun without a left-hand device.
  const std::int64_t first =
      left ? prepared(kLeftFrameCount,
                      "SELECT CASE WHEN left_device IS NULL THEN -1 ELSE left_frame_count END "
                      "FROM sessions WHERE id = ?1")
                 .bind(1, session)
                 .single_integer(looking.c_str())
           : prepared(kFrameCount, "SELECT frame_count FROM sessions WHERE id = ?1")
                 .bind(1, session)
                 .single_integer(looking.c_str());
  if (first < 0)
    throw error("session " + std::to_string(session) +
                " was begun without a left-hand device: it takes no left-hand frames");
  const std::vector<std::uint8_t> bytes = encode_frame_chunk(frames);
  (left ? prepared(kAddLeftChunk,
                   "INSERT INTO left_hand_frame_chunks (session_id, first_frame, frame_count, "
                   "first_time_s, last_time_s, layout, data) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)")
        : prepared(kAddChunk,
                   "INSERT INTO frame_chunks (session_id, first_frame, frame_count, first_time_s, "
                   "last_time_s, layout, data) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)"))
      .bind(1, session)
      .bind(2, first)
      .bind(3, static_cast<std::int64_t>(frames.size()))
      .bind(4, frames.front().time_s)
      .bind(5, frames.back().time_s)
      .bind(6, std::int64_t{kFrameChunkLayout})
      .bind(7, std::span<const std::uint8_t>(bytes))
      .run("storing frames");
  (left
       ? prepared(kCountLeftFrames,
                  "UPDATE sessions SET left_frame_count = left_frame_count + ?2 WHERE id = ?1")
       : prepared(kCountFrames, "UPDATE sessions SET frame_count = frame_count + ?2 WHERE id = ?1"))
      .bind(1, session)
      .bind(2, static_cast<std::int64_t>(frames.size()))
      .run("counting frames");
}

void SqliteSessionStore::append_events(std::int64_t session, std::span<const SessionEvent> events) {
  if (events.empty()) return;
  begin_if_needed();
  Statement& add = prepared(
      kAddEvent,
      "INSERT INTO events (session_id, time_s, kind, detail, hand) VALUES (?1, ?2, ?3, ?4, ?5)");
  for (const SessionEvent& event : events)
    add.bind(1, session)
        .bind(2, event.time_s)
        .bind(3, session_event_name(event.kind))
        .bind(4, std::string_view(event.detail))
        .bind(5, hand_name(event.hand))
        .run("storing an event");
}

void SqliteSessionStore::append_inputs(std::int64_t session,
                                       std::span<const SimulationInput> inputs) {
  if (inputs.empty()) return;
  begin_if_needed();
  const std::int64_t first =
      prepared(kInputCount, "SELECT input_count FROM sessions WHERE id = ?1")
          .bind(1, session)
          .single_integer(("looking up session " + std::to_string(session)).c_str());
  const std::vector<std::uint8_t> bytes = encode_input_chunk(inputs);
  prepared(kAddInputChunk,
           "INSERT INTO input_chunks (session_id, first_input, input_count, layout, data) "
           "VALUES (?1, ?2, ?3, ?4, ?5)")
      .bind(1, session)
      .bind(2, first)
      .bind(3, static_cast<std::int64_t>(inputs.size()))
      .bind(4, std::int64_t{kInputChunkLayout})
      .bind(5, std::span<const std::uint8_t>(bytes))
      .run("storing the simulation's input");
  prepared(kCountInputs, "UPDATE sessions SET input_count = input_count + ?2 WHERE id = ?1")
      .bind(1, session)
      .bind(2, static_cast<std::int64_t>(inputs.size()))
      .run("counting the simulation's input");
}

std::optional<ReplaySetup> SqliteSessionStore::replay_setup(std::int64_t session) {
  Statement& row =
      prepared(kReplay,
               "SELECT built_in_liver_tets, scenario_folder, integrator, step_s, tolerance_m, "
               "newton_tolerance_m, max_newton_iterations, loop_step_s FROM session_replays "
               "WHERE session_id = ?1");
  row.bind(1, session);
  if (!row.step("reading how to replay the session")) {
    row.reset();
    return std::nullopt;
  }
  ReplaySetup setup;
  if (!row.is_null(0)) setup.built_in_liver_tets = static_cast<int>(row.integer(0));
  setup.scenario_folder = row.text(1);
  const std::string integrator = row.text(2);
  const std::optional<IntegratorKind> kind = integrator_from_name(integrator);
  setup.integrator.step_s = row.real(3);
  setup.integrator.tolerance_m = row.real(4);
  setup.integrator.newton_tolerance_m = row.real(5);
  setup.integrator.max_newton_iterations = static_cast<int>(row.integer(6));
  if (!row.is_null(7)) setup.loop_step_s = row.real(7);
  row.reset();
  if (!kind)
    throw error("session " + std::to_string(session) + " was run with the integrator \"" +
                integrator + "\", which this version does not know");
  setup.integrator.kind = *kind;
  return setup;
}

std::vector<SimulationInput> SqliteSessionStore::inputs(std::int64_t session) {
  return chunks_of<SimulationInput>(session,
                                    prepared(kInputChunks,
                                             "SELECT first_input, layout, data FROM input_chunks "
                                             "WHERE session_id = ?1 ORDER BY first_input"),
                                    "inputs", kInputChunkLayout, decode_input_chunk);
}

void SqliteSessionStore::end_session(std::int64_t session, std::int64_t ended_unix_ms,
                                     const SessionServoFigures& servo,
                                     const std::optional<SessionServoFigures>& left_servo) {
  // Checked before anything is written: a refusal leaves the session as it was.
  if (left_servo &&
      prepared(kHasLeftHand, "SELECT left_device IS NOT NULL FROM sessions WHERE id = ?1")
              .bind(1, session)
              .single_integer(("looking up session " + std::to_string(session)).c_str()) == 0)
    throw error("session " + std::to_string(session) + " has no left-hand device");
  begin_if_needed();
  // The twelve figures, kServoColumns' order, from parameter `first` on.
  const auto bind_figures = [](Statement& statement, int first, const SessionServoFigures& f) {
    const auto count = [](std::uint64_t value) { return static_cast<std::int64_t>(value); };
    statement.bind(first, count(f.ticks))
        .bind(first + 1, f.rate_hz)
        .bind(first + 2, f.period_p50_ms)
        .bind(first + 3, f.period_p99_ms)
        .bind(first + 4, f.period_max_ms)
        .bind(first + 5, count(f.missed_deadlines))
        .bind(first + 6, count(f.force_clamps))
        .bind(first + 7, count(f.stiffness_clamps))
        .bind(first + 8, count(f.rate_limited))
        .bind(first + 9, count(f.watchdog_trips))
        .bind(first + 10, count(f.device_faults))
        .bind(first + 11, count(f.dropped_frames));
  };
  Statement& end =
      prepared(kEndSession,
               "UPDATE sessions SET status = 'complete', ended_unix_ms = ?2, servo_ticks = ?3, "
               "servo_rate_hz = ?4, servo_period_p50_ms = ?5, servo_period_p99_ms = ?6, "
               "servo_period_max_ms = ?7, missed_deadlines = ?8, force_clamps = ?9, "
               "stiffness_clamps = ?10, rate_limited = ?11, watchdog_trips = ?12, "
               "device_faults = ?13, dropped_frames = ?14 WHERE id = ?1");
  end.bind(1, session).bind(2, ended_unix_ms);
  bind_figures(end, 3, servo);
  end.run("ending the session");
  if (sqlite3_changes(db_) != 1) throw error("there is no session " + std::to_string(session));
  if (left_servo) {
    Statement end_left(*this, ("UPDATE sessions SET (" + stored_rows::kLeftServoColumns +
                               ") = (?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13) "
                               "WHERE id = ?1")
                                  .c_str());
    end_left.bind(1, session);
    bind_figures(end_left, 2, *left_servo);
    end_left.run("ending the session's left hand");
  }
  commit();
  if (sessions_recording_ > 0 && --sessions_recording_ == 0) release_recording_lock();
}

void SqliteSessionStore::store_metrics(std::int64_t session, std::span<const MetricValue> metrics) {
  begin_if_needed();
  Statement& store = prepared(
      kStoreMetric, "INSERT OR REPLACE INTO metrics (session_id, name, value) VALUES (?1, ?2, ?3)");
  for (const MetricValue& metric : metrics)
    store.bind(1, session)
        .bind(2, std::string_view(metric.name))
        .bind(3, metric.value)
        .run("storing a metric");
  commit();
}

std::vector<MetricValue> SqliteSessionStore::metrics(std::int64_t session) {
  Statement& rows =
      prepared(kMetrics, "SELECT name, value FROM metrics WHERE session_id = ?1 ORDER BY name");
  rows.bind(1, session);
  std::vector<MetricValue> result;
  while (rows.step("reading metrics")) result.push_back({rows.text(0), rows.real(1)});
  rows.reset();
  return result;
}

bool SqliteSessionStore::has_instructor_accounts() {
  return prepared(kAccountCount, "SELECT count(*) FROM instructor_accounts")
             .single_integer("counting instructor accounts") > 0;
}

std::optional<std::pair<std::int64_t, std::string>> SqliteSessionStore::account_of(
    std::string_view name) {
  Statement& find = prepared(kFindAccount,
                             "SELECT p.id, a.password_hash FROM instructor_accounts a "
                             "JOIN people p ON p.id = a.person_id "
                             "WHERE p.name = ?1 AND p.role = 'instructor'");
  find.bind(1, name);
  std::optional<std::pair<std::int64_t, std::string>> account;
  if (find.step("looking up the instructor account")) account = {find.integer(0), find.text(1)};
  find.reset();
  return account;
}

void SqliteSessionStore::require_account(const Instructor& instructor) {
  const std::int64_t accounts =
      prepared(kCheckGrader,
               "SELECT count(*) FROM instructor_accounts a JOIN people p ON p.id = a.person_id "
               "WHERE a.person_id = ?1 AND p.name = ?2")
          .bind(1, instructor.id())
          .bind(2, std::string_view(instructor.name()))
          .single_integer("checking the instructor");
  if (accounts != 1)
    throw AccessDenied("\"" + instructor.name() + "\" has no instructor account in " +
                       file_.string());
}

Instructor SqliteSessionStore::add_instructor_account(std::string_view name,
                                                      std::string_view password,
                                                      const Instructor* added_by) {
  if (name.empty()) throw std::invalid_argument("an instructor account needs a name");
  check_new_password(password);
  if (has_instructor_accounts()) {
    if (added_by == nullptr)
      throw AccessDenied("only an instructor who has logged in can add instructor accounts");
    require_account(*added_by);
  }
  if (account_of(name))
    throw std::invalid_argument("there is already an instructor account named \"" +
                                std::string(name) + "\"");
  const std::string hash = hash_password(password, password_cost_);  // slow: before the write
  begin_if_needed();
  const std::int64_t id = person(name, "instructor");
  prepared(kAddAccount,
           "INSERT INTO instructor_accounts (person_id, password_hash, created_unix_ms) "
           "VALUES (?1, ?2, ?3)")
      .bind(1, id)
      .bind(2, std::string_view(hash))
      .bind(3, stored_rows::unix_ms_now())
      .run("adding the instructor account");
  commit();
  return vouch_for(id, std::string(name));
}

std::optional<Instructor> SqliteSessionStore::log_in_instructor(std::string_view name,
                                                                std::string_view password) {
  const auto account = account_of(name);
  if (account)
    if (const std::optional<std::string> problem = stored_password_hash_problem(account->second))
      throw error("the password hash of the instructor account '" + std::string(name) +
                      "' cannot be checked (a damaged file?): " + *problem,
                  StorageProblem::damaged);
  // An unknown name costs a verification too, so that the time does not tell names apart.
  static const std::string unknown_name_hash = hash_password("no such account");
  const bool matches = password_matches(password, account ? account->second : unknown_name_hash);
  if (!account || !matches) return std::nullopt;
  return vouch_for(account->first, std::string(name));
}

void SqliteSessionStore::store_grade(const Instructor& by, std::int64_t session,
                                     const SessionGrade& grade) {
  require_account(by);
  const std::int64_t instructor = by.id();
  begin_if_needed();
  Statement& store = prepared(
      kStoreGrade,
      "INSERT INTO grades (session_id, instructor_id, graded_unix_ms, score, grade, comment, "
      "uuid) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)");
  store.bind(1, session).bind(2, instructor).bind(3, grade.graded_unix_ms);
  store.bind(7, std::string_view(new_uuid()));
  if (grade.score_percent)
    store.bind(4, *grade.score_percent);
  else
    store.bind_null(4);
  store.bind(5, std::string_view(grade.grade))
      .bind(6, std::string_view(grade.comment))
      .run("storing a grade");
  commit();
}

std::vector<SessionGrade> SqliteSessionStore::grades(std::int64_t session) {
  Statement& rows =
      prepared(kGrades,
               "SELECT p.name, g.graded_unix_ms, g.score, g.grade, g.comment FROM grades g "
               "JOIN people p ON p.id = g.instructor_id WHERE g.session_id = ?1 ORDER BY g.id");
  rows.bind(1, session);
  std::vector<SessionGrade> result;
  while (rows.step("reading grades")) result.push_back(stored_rows::session_grade(rows));
  rows.reset();
  return result;
}

std::vector<SessionSummary> SqliteSessionStore::sessions() {
  return list_sessions(std::nullopt);
}

std::vector<SessionSummary> SqliteSessionStore::sessions_of_trainee(std::string_view trainee) {
  return list_sessions(trainee);
}

std::vector<SessionSummary> SqliteSessionStore::list_sessions(
    std::optional<std::string_view> trainee) {
  static const std::string query =
      stored_rows::kSessionSummarySelect + "WHERE ?1 IS NULL OR p.name = ?1 ORDER BY s.id";
  Statement& rows = prepared(kSessions, query.c_str());
  if (trainee) rows.bind(1, *trainee);  // unbound: NULL, every trainee's
  std::vector<SessionSummary> result;
  while (rows.step("listing sessions")) result.push_back(stored_rows::session_summary(rows));
  rows.reset();
  return result;
}

template <typename Item, typename Decode>
std::vector<Item> SqliteSessionStore::chunks_of(std::int64_t session, Statement& chunks,
                                                const std::string& items, int layout, Decode decode,
                                                const ReadingProgress& progress,
                                                std::size_t total) {
  chunks.bind(1, session);
  std::vector<Item> result;  // not reserved from `total`: a damaged file may claim any count
  const auto report = [&] {
    if (progress && !progress(result.size(), total)) {
      chunks.reset();
      throw ReadingCancelled();
    }
  };
  report();
  try {
    while (chunks.step(("reading " + items).c_str())) {
      stored_rows::append_chunk(result, chunks.integer(0), chunks.integer(1), layout,
                                chunks.blob(2), items, decode);
      report();
    }
  } catch (const StorageError& e) {
    chunks.reset();
    // A chunk that does not decode, or is missing, is damage.
    throw error("session " + std::to_string(session) + ": " + e.what(),
                e.problem() == StorageProblem::other ? StorageProblem::damaged : e.problem());
  }
  chunks.reset();
  return result;
}

std::vector<ServoFrame> SqliteSessionStore::frames(std::int64_t session, Hand hand,
                                                   const ReadingProgress& progress) {
  const bool left = hand == Hand::left;
  std::size_t total = 0;
  if (progress) {
    total = static_cast<std::size_t>(
        (left ? prepared(kLeftChunkFrameSum,
                         "SELECT COALESCE(SUM(frame_count), 0) FROM left_hand_frame_chunks "
                         "WHERE session_id = ?1")
              : prepared(kChunkFrameSum,
                         "SELECT COALESCE(SUM(frame_count), 0) FROM frame_chunks "
                         "WHERE session_id = ?1"))
            .bind(1, session)
            .single_integer("counting frames"));
  }
  return chunks_of<ServoFrame>(
      session,
      left ? prepared(kLeftChunks,
                      "SELECT first_frame, layout, data FROM left_hand_frame_chunks "
                      "WHERE session_id = ?1 ORDER BY first_frame")
           : prepared(kChunks,
                      "SELECT first_frame, layout, data FROM frame_chunks "
                      "WHERE session_id = ?1 ORDER BY first_frame"),
      left ? "left-hand frames" : "frames", kFrameChunkLayout, decode_frame_chunk, progress, total);
}

std::vector<SessionEvent> SqliteSessionStore::events(std::int64_t session) {
  Statement& rows = prepared(
      kEvents,
      "SELECT time_s, kind, detail, hand FROM events WHERE session_id = ?1 ORDER BY time_s, id");
  rows.bind(1, session);
  std::vector<SessionEvent> result;
  while (rows.step("reading events")) {
    try {
      result.push_back(
          stored_rows::session_event(rows.real(0), rows.text(1), rows.text(2), rows.text(3)));
    } catch (const StorageError& e) {
      rows.reset();
      throw error("session " + std::to_string(session) + " " + e.what());
    }
  }
  rows.reset();
  return result;
}

std::string SqliteSessionStore::scenario_text(std::int64_t session) {
  Statement& row = prepared(kScenarioText,
                            "SELECT c.content FROM sessions s JOIN scenarios c "
                            "ON c.id = s.scenario_id WHERE s.id = ?1");
  row.bind(1, session);
  if (!row.step("reading the scenario")) {
    row.reset();
    throw error("there is no session " + std::to_string(session));
  }
  std::string text = row.text(0);
  row.reset();
  return text;
}

std::vector<std::int64_t> SqliteSessionStore::sessions_to_upload(std::string_view server) {
  Statement rows(*this,
                 "SELECT s.id FROM sessions s WHERE s.status <> 'recording' AND NOT EXISTS "
                 "(SELECT 1 FROM session_uploads u WHERE u.session_id = s.id AND u.server = ?1 "
                 "AND u.uploaded_unix_ms IS NOT NULL) AND (s.status <> 'complete' OR EXISTS "
                 "(SELECT 1 FROM metrics m WHERE m.session_id = s.id) OR s.ended_unix_ms < ?2) "
                 "ORDER BY s.id");
  rows.bind(1, server);
  rows.bind(2, stored_rows::unix_ms_now() - kMetricsWaitMs);
  std::vector<std::int64_t> result;
  while (rows.step("listing the sessions to upload")) result.push_back(rows.integer(0));
  return result;
}

SessionTransfer SqliteSessionStore::transfer_of(std::int64_t session) {
  SessionTransfer transfer;
  {
    Statement row(*this, (stored_rows::kSessionSummarySelect + "WHERE s.id = ?1").c_str());
    row.bind(1, session);
    if (!row.step("reading the session"))
      throw error("there is no session " + std::to_string(session));
    transfer.summary = stored_rows::session_summary(row);
  }
  transfer.input_count = Statement(*this, "SELECT input_count FROM sessions WHERE id = ?1")
                             .bind(1, session)
                             .single_integer("counting the session's inputs");
  transfer.scenario_text = scenario_text(session);
  transfer.replay = replay_setup(session);
  transfer.events = events(session);
  transfer.metrics = metrics(session);
  const auto chunks = [this, session](const char* sql, bool timed) {
    return [this, session, sql, timed](const ChunkSink& sink) {
      Statement rows(*this, sql);
      rows.bind(1, session);
      StoredChunk chunk;
      while (rows.step("reading the chunks to upload")) {
        chunk.first = rows.integer(0);
        chunk.count = rows.integer(1);
        // A damaged file's row is refused here, not handed on to be uploaded.
        if (chunk.first < 0 || chunk.count < 0)
          throw error("session " + std::to_string(session) + " has a chunk starting at " +
                          std::to_string(chunk.first) + " with " + std::to_string(chunk.count) +
                          " entries: the file is damaged",
                      StorageProblem::damaged);
        chunk.layout = static_cast<int>(rows.integer(2));
        const std::span<const std::uint8_t> data = rows.blob(3);
        chunk.data.assign(data.begin(), data.end());
        if (timed) {
          chunk.first_time_s = rows.real(4);
          chunk.last_time_s = rows.real(5);
        }
        sink(chunk);
      }
    };
  };
  transfer.frame_chunks = chunks(
      "SELECT first_frame, frame_count, layout, data, first_time_s, last_time_s FROM "
      "frame_chunks WHERE session_id = ?1 ORDER BY first_frame",
      true);
  transfer.left_frame_chunks = chunks(
      "SELECT first_frame, frame_count, layout, data, first_time_s, last_time_s FROM "
      "left_hand_frame_chunks WHERE session_id = ?1 ORDER BY first_frame",
      true);
  transfer.input_chunks = chunks(
      "SELECT first_input, input_count, layout, data FROM input_chunks WHERE session_id = ?1 "
      "ORDER BY first_input",
      false);
  return transfer;
}

void SqliteSessionStore::mark_uploaded(std::int64_t session, std::string_view server,
                                       std::int64_t unix_ms) {
  begin_if_needed();
  Statement(*this,
            "INSERT INTO session_uploads (session_id, server, uploaded_unix_ms, attempts) "
            "VALUES (?1, ?2, ?3, 1) ON CONFLICT (session_id, server) DO UPDATE SET "
            "uploaded_unix_ms = ?3, attempts = attempts + 1, last_problem = NULL")
      .bind(1, session)
      .bind(2, server)
      .bind(3, unix_ms)
      .run("noting the upload");
  commit();
}

void SqliteSessionStore::note_upload_problem(std::int64_t session, std::string_view server,
                                             std::string_view problem) {
  begin_if_needed();
  Statement(*this,
            "INSERT INTO session_uploads (session_id, server, attempts, last_problem) "
            "VALUES (?1, ?2, 1, ?3) ON CONFLICT (session_id, server) DO UPDATE SET "
            "attempts = attempts + 1, last_problem = ?3")
      .bind(1, session)
      .bind(2, server)
      .bind(3, problem)
      .run("noting the upload's problem");
  commit();
}

SqliteSessionStore::UploadState SqliteSessionStore::upload_state(std::int64_t session,
                                                                 std::string_view server) {
  Statement row(*this,
                "SELECT uploaded_unix_ms, attempts, last_problem FROM session_uploads "
                "WHERE session_id = ?1 AND server = ?2");
  row.bind(1, session).bind(2, server);
  UploadState state;
  if (row.step("reading the upload's state")) {
    if (!row.is_null(0)) state.uploaded_unix_ms = row.integer(0);
    state.attempts = row.integer(1);
    state.last_problem = row.text(2);
  }
  return state;
}

std::vector<std::string> SqliteSessionStore::uploaded_session_uuids(std::string_view server) {
  Statement rows(*this,
                 "SELECT s.uuid FROM sessions s JOIN session_uploads u ON u.session_id = s.id "
                 "WHERE u.server = ?1 AND u.uploaded_unix_ms IS NOT NULL ORDER BY s.id");
  rows.bind(1, server);
  std::vector<std::string> result;
  while (rows.step("listing the uploaded sessions")) result.push_back(rows.text(0));
  return result;
}

int SqliteSessionStore::store_shared_grades(std::span<const SharedGrade> grades) {
  begin_if_needed();
  int added = 0;
  Statement add(*this,
                "INSERT OR IGNORE INTO grades (session_id, instructor_id, graded_unix_ms, score, "
                "grade, comment, uuid) SELECT s.id, ?2, ?3, ?4, ?5, ?6, ?7 FROM sessions s "
                "WHERE s.uuid = ?1");
  for (const SharedGrade& shared : grades) {
    const std::int64_t instructor = person(shared.grade.instructor, "instructor");
    add.bind(1, std::string_view(shared.session_uuid))
        .bind(2, instructor)
        .bind(3, shared.grade.graded_unix_ms);
    if (shared.grade.score_percent)
      add.bind(4, *shared.grade.score_percent);
    else
      add.bind_null(4);
    add.bind(5, std::string_view(shared.grade.grade))
        .bind(6, std::string_view(shared.grade.comment))
        .bind(7, std::string_view(shared.grade_uuid))
        .run("storing a grade from the server");
    added += sqlite3_changes(db_);
  }
  commit();
  return added;
}

}  // namespace liversim
