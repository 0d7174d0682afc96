#pragma once
// The training centre's session store: the same interface and schema as the embedded one, on a
// PostgreSQL server (libpq, bound parameters only). Workstations record in their own SQLite file
// and upload finished sessions here (session_upload.h); instructors review and grade here from
// anywhere. The server enforces the roles too (docs/training-centre.md): a workstation's login may
// add sessions and read, an instructor's may grade and publish scenarios, in their own name only.

#include "liversim/sessions/session_store.h"
#include "liversim/storage/server_settings.h"
#include "liversim/storage/session_transfer.h"

#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace liversim {

// A scenario instructors published on the server, which workstations pull.
struct PublishedScenario {
  std::string name;  // the file name it is pulled to, without ".json"
  std::string title;
  std::string text;  // the scenario file's content
  std::string sha256;
  std::int64_t version = 0;  // 1, then one more each time it is published again
  std::string published_by;
  std::int64_t published_unix_ms = 0;
};

// The kinds of server login LiverSim sets up (server roles liversim_workstation and
// liversim_instructor).
enum class ServerLoginKind { workstation, instructor };

class PostgresSessionStore final : public SessionStore {
 public:
  // The schema version this build reads and writes (table liversim_schema on the server).
  static constexpr int kSchemaVersion = 4;

  // Connects as settings.user with this password (empty: libpq finds one in ~/.pgpass or uses a
  // client certificate). Throws StorageError naming the server: unreachable (no answer, TLS
  // refused), refused (the login), not_a_database (no LiverSim schema: the administrator runs
  // `liversim-cli server set-up`), newer_version, or an older schema the administrator must
  // migrate.
  PostgresSessionStore(const ServerSettings& settings, std::string_view password);
  ~PostgresSessionStore() override;
  PostgresSessionStore(const PostgresSessionStore&) = delete;
  PostgresSessionStore& operator=(const PostgresSessionStore&) = delete;

  // For the server's administrator (a role that may create roles and owns the database): creates
  // the roles liversim_workstation and liversim_instructor if missing and the schema, or migrates
  // it, up to `version` (tests stop at an earlier one). Each step is one transaction.
  static void set_up_server(const ServerSettings& administrator, std::string_view password,
                            int version = kSchemaVersion);
  // The administrator adds a login: a workstation's or an instructor's. The password is sent
  // only as its SCRAM-SHA-256 verifier.
  static void add_server_login(const ServerSettings& administrator,
                               std::string_view administrator_password, std::string_view name,
                               std::string_view password, ServerLoginKind kind);

  const ServerSettings& settings() const { return settings_; }
  int schema_version();
  // Whether the connection is TLS (the settings' ssl_mode decides whether it must be).
  bool connection_is_encrypted() const;

  // Upload: stores the session, its chunks, events and metrics in one transaction. True when it
  // is stored now; false when a session of that UUID was there already (nothing is added).
  bool receive_session(const SessionTransfer& session);
  bool has_session(std::string_view uuid);
  // The grades of these sessions (by UUID), oldest first.
  std::vector<SharedGrade> grades_of_sessions(std::span<const std::string> session_uuids);

  // Scenarios: an instructor publishes (a new version of) one under a name (letters, digits, '.',
  // '_', '-': the file it is pulled to); its title is the scenario's. A text that is not a valid
  // scenario is refused (std::invalid_argument, naming its errors); anyone reads them.
  void publish_scenario(const Instructor& by, std::string_view name, std::string_view text);
  std::vector<PublishedScenario> published_scenarios();

  // SessionStore. Writing sessions directly is what an upload does, in steps; a workstation's
  // login may only add to a session it began, while it is recording.
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

  // Instructor accounts are server logins: the password is checked by the server (SCRAM), and the
  // instructor's own connection does what only instructors may. An account is added by an
  // instructor who logged in (or the administrator: add_server_login), never by anyone.
  Instructor add_instructor_account(std::string_view name, std::string_view password,
                                    const Instructor* added_by) override;
  bool has_instructor_accounts() override;
  std::optional<Instructor> log_in_instructor(std::string_view name,
                                              std::string_view password) override;
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

  class Connection;  // a libpq connection (postgres_session_store.cpp)

 private:
  std::vector<SessionSummary> list_sessions(std::optional<std::string_view> trainee);
  // The connection an instructor logged in with (AccessDenied when not of this store).
  Connection& connection_of(const Instructor& instructor);

  ServerSettings settings_;
  std::unique_ptr<Connection> connection_;
  std::map<std::int64_t, std::unique_ptr<Connection>> instructors_;
};

}  // namespace liversim
