#include "liversim/storage/postgres_session_store.h"

#include "liversim/engine/integrator.h"
#include "liversim/scenario/scenario.h"
#include "liversim/storage/password_hash.h"
#include "liversim/storage/sha256.h"
#include "stored_rows.h"

#include <libpq-fe.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace liversim {

using stored_rows::kMappingColumns;
using stored_rows::kServoColumns;

namespace {

// kMigrations[v] takes the server's schema from version v to v + 1 (0: none yet), with the
// server's own enforcement of the roles (docs/training-centre.md). The tables are those of the
// embedded store (sqlite_session_store.cpp); sessions and grades have UUIDs, so that a copy
// uploaded again or pulled again is recognised.
constexpr const char* kServerSchemaV1 = R"sql(
CREATE TABLE liversim_schema (version integer NOT NULL);
INSERT INTO liversim_schema VALUES (0);
CREATE TABLE people (
  id bigserial PRIMARY KEY,
  name text NOT NULL,
  role text NOT NULL CHECK (role IN ('trainee', 'instructor')),
  UNIQUE (name, role)
);
CREATE TABLE scenarios (
  id bigserial PRIMARY KEY,
  sha256 text NOT NULL UNIQUE,
  title text NOT NULL,
  content text NOT NULL
);
CREATE TABLE sessions (
  id bigserial PRIMARY KEY,
  uuid uuid NOT NULL UNIQUE,
  trainee_id bigint NOT NULL REFERENCES people (id),
  scenario_id bigint NOT NULL REFERENCES scenarios (id),
  device text NOT NULL,
  started_unix_ms bigint NOT NULL,
  ended_unix_ms bigint,
  status text NOT NULL CHECK (status IN ('recording', 'complete', 'incomplete')),
  frame_count bigint NOT NULL DEFAULT 0,
  input_count bigint NOT NULL DEFAULT 0,
  servo_ticks bigint,
  servo_rate_hz double precision,
  servo_period_p50_ms double precision,
  servo_period_p99_ms double precision,
  servo_period_max_ms double precision,
  missed_deadlines bigint,
  force_clamps bigint,
  stiffness_clamps bigint,
  rate_limited bigint,
  watchdog_trips bigint,
  device_faults bigint,
  dropped_frames bigint,
  mapping_scale double precision,
  mapping_rotation_w double precision,
  mapping_rotation_x double precision,
  mapping_rotation_y double precision,
  mapping_rotation_z double precision,
  mapping_offset_x_m double precision,
  mapping_offset_y_m double precision,
  mapping_offset_z_m double precision,
  -- Who sent it and in which transaction: what a login may add to (the policies below).
  uploaded_by text NOT NULL DEFAULT session_user,
  upload_transaction xid8 NOT NULL DEFAULT pg_current_xact_id(),
  uploaded_unix_ms bigint NOT NULL DEFAULT (extract(epoch FROM now()) * 1000)::bigint
);
CREATE TABLE frame_chunks (
  session_id bigint NOT NULL REFERENCES sessions (id),
  first_frame bigint NOT NULL,
  frame_count bigint NOT NULL,
  first_time_s double precision NOT NULL,
  last_time_s double precision NOT NULL,
  layout bigint NOT NULL,
  data bytea NOT NULL,
  PRIMARY KEY (session_id, first_frame)
);
CREATE TABLE events (
  id bigserial PRIMARY KEY,
  session_id bigint NOT NULL REFERENCES sessions (id),
  time_s double precision NOT NULL,
  kind text NOT NULL,
  detail text NOT NULL
);
CREATE INDEX events_by_session ON events (session_id, time_s);
CREATE TABLE metrics (
  session_id bigint NOT NULL REFERENCES sessions (id),
  name text NOT NULL,
  value double precision NOT NULL,
  PRIMARY KEY (session_id, name)
);
CREATE TABLE grades (
  id bigserial PRIMARY KEY,
  uuid uuid NOT NULL UNIQUE DEFAULT gen_random_uuid(),
  session_id bigint NOT NULL REFERENCES sessions (id),
  instructor_id bigint NOT NULL REFERENCES people (id),
  graded_unix_ms bigint NOT NULL,
  score double precision,
  grade text NOT NULL,
  comment text NOT NULL
);
CREATE TABLE session_replays (
  session_id bigint PRIMARY KEY REFERENCES sessions (id),
  built_in_liver_tets bigint,
  scenario_folder text NOT NULL,
  integrator text NOT NULL,
  step_s double precision NOT NULL,
  tolerance_m double precision NOT NULL,
  newton_tolerance_m double precision NOT NULL,
  max_newton_iterations bigint NOT NULL
);
CREATE TABLE input_chunks (
  session_id bigint NOT NULL REFERENCES sessions (id),
  first_input bigint NOT NULL,
  input_count bigint NOT NULL,
  layout bigint NOT NULL,
  data bytea NOT NULL,
  PRIMARY KEY (session_id, first_input)
);

-- A session a login may add to: one it sent, while it records or in the transaction that
-- uploads it.
CREATE FUNCTION liversim_may_add_to(session bigint) RETURNS boolean
  LANGUAGE sql STABLE SECURITY DEFINER SET search_path = public, pg_temp AS $$
  SELECT EXISTS (SELECT 1 FROM sessions s WHERE s.id = session AND s.uploaded_by = session_user
                 AND (s.status = 'recording' OR s.upload_transaction = pg_current_xact_id()))
$$;
REVOKE ALL ON FUNCTION liversim_may_add_to(bigint) FROM PUBLIC;
GRANT EXECUTE ON FUNCTION liversim_may_add_to(bigint) TO liversim_workstation, liversim_instructor;

-- Instructors add instructors; the password arrives as a SCRAM verifier only.
CREATE FUNCTION liversim_add_instructor(login text, verifier text) RETURNS bigint
  LANGUAGE plpgsql SECURITY DEFINER SET search_path = public, pg_temp AS $$
DECLARE
  person bigint;
BEGIN
  IF verifier NOT LIKE 'SCRAM-SHA-256$%' THEN
    RAISE EXCEPTION 'an instructor password must arrive as a SCRAM-SHA-256 verifier';
  END IF;
  EXECUTE format('CREATE ROLE %I LOGIN PASSWORD %L IN ROLE liversim_instructor', login, verifier);
  INSERT INTO people (name, role) VALUES (login, 'instructor')
    ON CONFLICT (name, role) DO UPDATE SET name = EXCLUDED.name RETURNING id INTO person;
  RETURN person;
END
$$;
REVOKE ALL ON FUNCTION liversim_add_instructor(text, text) FROM PUBLIC;
GRANT EXECUTE ON FUNCTION liversim_add_instructor(text, text) TO liversim_instructor;

GRANT SELECT ON liversim_schema, people, scenarios, sessions, frame_chunks, events, metrics,
  grades, session_replays, input_chunks TO liversim_workstation, liversim_instructor;
GRANT INSERT ON people, scenarios, sessions, frame_chunks, events, metrics, session_replays,
  input_chunks TO liversim_workstation;
GRANT UPDATE (frame_count, input_count, status, ended_unix_ms, servo_ticks, servo_rate_hz,
  servo_period_p50_ms, servo_period_p99_ms, servo_period_max_ms, missed_deadlines, force_clamps,
  stiffness_clamps, rate_limited, watchdog_trips, device_faults, dropped_frames)
  ON sessions TO liversim_workstation;
GRANT UPDATE (value) ON metrics TO liversim_workstation;
GRANT INSERT ON grades TO liversim_instructor;
GRANT USAGE ON ALL SEQUENCES IN SCHEMA public TO liversim_workstation, liversim_instructor;

ALTER TABLE people ENABLE ROW LEVEL SECURITY;
CREATE POLICY anyone_reads ON people FOR SELECT USING (true);
CREATE POLICY workstations_add_trainees ON people FOR INSERT TO liversim_workstation
  WITH CHECK (role = 'trainee');
ALTER TABLE sessions ENABLE ROW LEVEL SECURITY;
CREATE POLICY anyone_reads ON sessions FOR SELECT USING (true);
CREATE POLICY sent_in_ones_own_name ON sessions FOR INSERT TO liversim_workstation
  WITH CHECK (uploaded_by = session_user AND upload_transaction = pg_current_xact_id());
CREATE POLICY only_while_recording ON sessions FOR UPDATE TO liversim_workstation
  USING (uploaded_by = session_user AND status = 'recording')
  WITH CHECK (uploaded_by = session_user);
ALTER TABLE grades ENABLE ROW LEVEL SECURITY;
CREATE POLICY anyone_reads ON grades FOR SELECT USING (true);
CREATE POLICY in_ones_own_name ON grades FOR INSERT TO liversim_instructor
  WITH CHECK (instructor_id = (SELECT id FROM people WHERE name = session_user
                                AND role = 'instructor'));
)sql";

// The tables of a session's parts take rows only for a session the login may add to: a trigger,
// not a policy, since COPY (the upload's way) refuses tables with row-level security.
constexpr const char* kServerSchemaV1Parts = R"sql(
CREATE FUNCTION liversim_check_may_add() RETURNS trigger
  LANGUAGE plpgsql SET search_path = public, pg_temp AS $$
BEGIN
  IF NOT liversim_may_add_to(NEW.session_id) THEN
    RAISE EXCEPTION USING ERRCODE = 'insufficient_privilege',
      MESSAGE = format('%s may not add to session %s of %s: only to a session it is sending',
                       session_user, NEW.session_id, TG_TABLE_NAME);
  END IF;
  RETURN NEW;
END
$$;
CREATE TRIGGER only_to_ones_own_session BEFORE INSERT ON frame_chunks
  FOR EACH ROW EXECUTE FUNCTION liversim_check_may_add();
CREATE TRIGGER only_to_ones_own_session BEFORE INSERT ON input_chunks
  FOR EACH ROW EXECUTE FUNCTION liversim_check_may_add();
CREATE TRIGGER only_to_ones_own_session BEFORE INSERT ON events
  FOR EACH ROW EXECUTE FUNCTION liversim_check_may_add();
CREATE TRIGGER only_to_ones_own_session BEFORE INSERT OR UPDATE ON metrics
  FOR EACH ROW EXECUTE FUNCTION liversim_check_may_add();
CREATE TRIGGER only_to_ones_own_session BEFORE INSERT ON session_replays
  FOR EACH ROW EXECUTE FUNCTION liversim_check_may_add();
)sql";

// Version 2: scenarios that instructors publish for the workstations to pull.
constexpr const char* kServerSchemaV2 = R"sql(
CREATE TABLE published_scenarios (
  name text PRIMARY KEY CHECK (name ~ '^[A-Za-z0-9][A-Za-z0-9._-]{0,99}$'),
  title text NOT NULL,
  content text NOT NULL,
  sha256 text NOT NULL,
  version bigint NOT NULL DEFAULT 1,
  published_by text NOT NULL DEFAULT session_user,
  published_unix_ms bigint NOT NULL
);
GRANT SELECT ON published_scenarios TO liversim_workstation, liversim_instructor;
GRANT INSERT, UPDATE (title, content, sha256, version, published_by, published_unix_ms)
  ON published_scenarios TO liversim_instructor;
ALTER TABLE published_scenarios ENABLE ROW LEVEL SECURITY;
CREATE POLICY anyone_reads ON published_scenarios FOR SELECT USING (true);
CREATE POLICY in_ones_own_name ON published_scenarios FOR INSERT TO liversim_instructor
  WITH CHECK (published_by = session_user);
CREATE POLICY republished_in_ones_own_name ON published_scenarios FOR UPDATE
  TO liversim_instructor USING (true) WITH CHECK (published_by = session_user);
)sql";

// Version 3: the real-time loop's step a session was recorded with (sqlite_session_store.cpp's
// version 6).
constexpr const char* kServerSchemaV3 = R"sql(
ALTER TABLE session_replays ADD COLUMN loop_step_s double precision;
)sql";

// Version 4: the left hand (sqlite_session_store.cpp's version 7): its device, mapping, frame count
// and servo figures in sessions, its frames in chunks of their own, and the hand of each event.
constexpr const char* kServerSchemaV4 = R"sql(
ALTER TABLE sessions ADD COLUMN left_device text;
ALTER TABLE sessions ADD COLUMN left_frame_count bigint NOT NULL DEFAULT 0;
ALTER TABLE sessions ADD COLUMN left_mapping_scale double precision;
ALTER TABLE sessions ADD COLUMN left_mapping_rotation_w double precision;
ALTER TABLE sessions ADD COLUMN left_mapping_rotation_x double precision;
ALTER TABLE sessions ADD COLUMN left_mapping_rotation_y double precision;
ALTER TABLE sessions ADD COLUMN left_mapping_rotation_z double precision;
ALTER TABLE sessions ADD COLUMN left_mapping_offset_x_m double precision;
ALTER TABLE sessions ADD COLUMN left_mapping_offset_y_m double precision;
ALTER TABLE sessions ADD COLUMN left_mapping_offset_z_m double precision;
ALTER TABLE sessions ADD COLUMN left_servo_ticks bigint;
ALTER TABLE sessions ADD COLUMN left_servo_rate_hz double precision;
ALTER TABLE sessions ADD COLUMN left_servo_period_p50_ms double precision;
ALTER TABLE sessions ADD COLUMN left_servo_period_p99_ms double precision;
ALTER TABLE sessions ADD COLUMN left_servo_period_max_ms double precision;
ALTER TABLE sessions ADD COLUMN left_missed_deadlines bigint;
ALTER TABLE sessions ADD COLUMN left_force_clamps bigint;
ALTER TABLE sessions ADD COLUMN left_stiffness_clamps bigint;
ALTER TABLE sessions ADD COLUMN left_rate_limited bigint;
ALTER TABLE sessions ADD COLUMN left_watchdog_trips bigint;
ALTER TABLE sessions ADD COLUMN left_device_faults bigint;
ALTER TABLE sessions ADD COLUMN left_dropped_frames bigint;
CREATE TABLE left_hand_frame_chunks (
  session_id bigint NOT NULL REFERENCES sessions (id),
  first_frame bigint NOT NULL,
  frame_count bigint NOT NULL,
  first_time_s double precision NOT NULL,
  last_time_s double precision NOT NULL,
  layout bigint NOT NULL,
  data bytea NOT NULL,
  PRIMARY KEY (session_id, first_frame)
);
ALTER TABLE events ADD COLUMN hand text NOT NULL DEFAULT 'right'
  CHECK (hand IN ('right', 'left'));
CREATE TRIGGER only_to_ones_own_session BEFORE INSERT ON left_hand_frame_chunks
  FOR EACH ROW EXECUTE FUNCTION liversim_check_may_add();
GRANT SELECT ON left_hand_frame_chunks TO liversim_workstation, liversim_instructor;
GRANT INSERT ON left_hand_frame_chunks TO liversim_workstation;
GRANT UPDATE (left_frame_count, left_servo_ticks, left_servo_rate_hz, left_servo_period_p50_ms,
  left_servo_period_p99_ms, left_servo_period_max_ms, left_missed_deadlines, left_force_clamps,
  left_stiffness_clamps, left_rate_limited, left_watchdog_trips, left_device_faults,
  left_dropped_frames) ON sessions TO liversim_workstation;
)sql";

struct Migration {
  std::array<const char*, 2> steps;
};
constexpr std::array<Migration, 4> kServerMigrations = {
    Migration{{kServerSchemaV1, kServerSchemaV1Parts}}, Migration{{kServerSchemaV2, nullptr}},
    Migration{{kServerSchemaV3, nullptr}}, Migration{{kServerSchemaV4, nullptr}}};
static_assert(kServerMigrations.size() == PostgresSessionStore::kSchemaVersion);

// Type OIDs of the parameters and columns (pg_type.h: server headers, not libpq's).
constexpr Oid kBoolOid = 16, kByteaOid = 17, kInt8Oid = 20, kInt4Oid = 23, kTextOid = 25,
              kFloat8Oid = 701;

template <typename T>
T big_endian(T value) {
  if constexpr (std::endian::native == std::endian::little) {
    auto bytes = std::bit_cast<std::array<std::uint8_t, sizeof(T)>>(value);
    std::reverse(bytes.begin(), bytes.end());
    return std::bit_cast<T>(bytes);
  } else {
    return value;
  }
}

// Parameters of a query, in binary (exact for doubles; bytea as it is).
class Params {
 public:
  Params& add(std::int64_t value) {
    return add_bytes(kInt8Oid, &(value = big_endian(value)), sizeof value);
  }
  Params& add(double value) {
    const std::uint64_t bits = big_endian(std::bit_cast<std::uint64_t>(value));
    return add_bytes(kFloat8Oid, &bits, sizeof bits);
  }
  Params& add(std::string_view text) { return add_bytes(kTextOid, text.data(), text.size()); }
  Params& add(std::span<const std::uint8_t> bytes) {
    return add_bytes(kByteaOid, bytes.data(), bytes.size());
  }
  template <typename T>
  Params& add(const std::optional<T>& value) {
    if (value) return add(*value);
    null_.push_back(true);
    types_.push_back(std::is_same_v<T, double>         ? kFloat8Oid
                     : std::is_same_v<T, std::int64_t> ? kInt8Oid
                                                       : kTextOid);
    storage_.emplace_back();
    return *this;
  }
  int size() const { return static_cast<int>(types_.size()); }
  const Oid* types() const { return types_.data(); }
  // Pointers into the storage, made when the query is sent (the storage no longer moves).
  void point(std::vector<const char*>& values, std::vector<int>& lengths,
             std::vector<int>& formats) const {
    values.clear();
    lengths.clear();
    formats.assign(types_.size(), 1);
    for (std::size_t i = 0; i < storage_.size(); ++i) {
      values.push_back(null_[i] ? nullptr : storage_[i].data());
      lengths.push_back(static_cast<int>(storage_[i].size()));
    }
  }

 private:
  Params& add_bytes(Oid type, const void* data, std::size_t size) {
    storage_.emplace_back(static_cast<const char*>(data), size);
    types_.push_back(type);
    null_.push_back(false);
    return *this;
  }
  std::vector<std::string> storage_;
  std::vector<Oid> types_;
  std::vector<bool> null_;
};

// A result with binary columns.
class Result {
 public:
  explicit Result(PGresult* result) : result_(result) {}
  ~Result() { PQclear(result_); }
  Result(Result&& other) noexcept : result_(std::exchange(other.result_, nullptr)) {}
  Result& operator=(Result&&) = delete;
  PGresult* raw() const { return result_; }
  int rows() const { return PQntuples(result_); }
  // Row r, as stored_rows' readers take one.
  struct Row {
    const Result& result;
    int row;
    std::int64_t integer(int column) const { return result.integer(row, column); }
    double real(int column) const { return result.real(row, column); }
    std::string text(int column) const { return result.text(row, column); }
    bool is_null(int column) const { return result.is_null(row, column); }
  };
  Row row(int r) const { return {*this, r}; }
  bool is_null(int row, int column) const { return PQgetisnull(result_, row, column) == 1; }
  std::int64_t integer(int row, int column) const {
    const char* data = PQgetvalue(result_, row, column);
    switch (PQftype(result_, column)) {
      case kInt8Oid: {
        std::int64_t value;
        std::memcpy(&value, data, sizeof value);
        return big_endian(value);
      }
      case kInt4Oid: {
        std::int32_t value;
        std::memcpy(&value, data, sizeof value);
        return big_endian(value);
      }
      case kBoolOid:
        return data[0] != 0;
      default:
        throw StorageError("the server answered a column of type " +
                           std::to_string(PQftype(result_, column)) + " where a number was due");
    }
  }
  double real(int row, int column) const {
    if (PQftype(result_, column) != kFloat8Oid)
      throw StorageError("the server answered a column of type " +
                         std::to_string(PQftype(result_, column)) + " where a real was due");
    std::uint64_t bits;
    std::memcpy(&bits, PQgetvalue(result_, row, column), sizeof bits);
    return std::bit_cast<double>(big_endian(bits));
  }
  std::string text(int row, int column) const {
    return std::string(PQgetvalue(result_, row, column),
                       static_cast<std::size_t>(PQgetlength(result_, row, column)));
  }
  std::span<const std::uint8_t> bytes(int row, int column) const {
    return {reinterpret_cast<const std::uint8_t*>(PQgetvalue(result_, row, column)),
            static_cast<std::size_t>(PQgetlength(result_, row, column))};
  }

 private:
  PGresult* result_;
};

std::string trimmed(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

}  // namespace

// One libpq connection and what is done on it: queries with bound parameters, transactions,
// COPY; every failure named with the server and turned into StorageError or AccessDenied.
class PostgresSessionStore::Connection {
 public:
  Connection(const ServerSettings& settings, std::string_view password) : settings_(settings) {
    const std::string port = std::to_string(settings.port);
    const std::string timeout = std::to_string(settings.connect_timeout_s);
    const std::string root_cert = settings.ssl_root_cert.string();
    const std::string cert = settings.ssl_cert.string();
    const std::string key = settings.ssl_key.string();
    const std::string password_text(password);
    std::vector<const char*> keys, values;
    const auto set = [&](const char* k, const std::string& v) {
      if (v.empty()) return;
      keys.push_back(k);
      values.push_back(v.c_str());
    };
    set("host", settings.host);
    set("port", port);
    set("dbname", settings.database);
    set("user", settings.user);
    set("password", password_text);
    set("sslmode", settings.ssl_mode);
    set("sslrootcert", root_cert);
    set("sslcert", cert);
    set("sslkey", key);
    set("connect_timeout", timeout);
    keys.push_back("application_name");
    values.push_back("liversim");
    keys.push_back(nullptr);
    values.push_back(nullptr);
    connection_ = PQconnectdbParams(keys.data(), values.data(), 0);
    if (connection_ == nullptr) throw error("cannot connect (out of memory)");
    if (PQstatus(connection_) != CONNECTION_OK) {
      const std::string reason = trimmed(PQerrorMessage(connection_));
      PQfinish(connection_);
      connection_ = nullptr;
      // libpq says "password authentication failed" (SQLSTATE 28P01, not readable here) for a
      // wrong name or password alike.
      const bool refused = reason.find("authentication failed") != std::string::npos ||
                           reason.find("no password supplied") != std::string::npos ||
                           reason.find("no pg_hba.conf entry") != std::string::npos;
      throw error(std::string(refused ? "the server refused the login" : "cannot connect") + " (" +
                      reason + ")",
                  refused ? StorageProblem::refused : StorageProblem::unreachable);
    }
  }
  ~Connection() {
    if (connection_) PQfinish(connection_);
  }
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  PGconn* raw() const { return connection_; }
  const ServerSettings& settings() const { return settings_; }

  StorageError error(const std::string& what,
                     StorageProblem problem = StorageProblem::other) const {
    return StorageError("server " + server_name(settings_) + ": " + what, problem);
  }

  // Runs the query; throws naming `doing` unless it succeeded.
  Result run(const char* sql, const Params& params, const std::string& doing) {
    std::vector<const char*> values;
    std::vector<int> lengths, formats;
    params.point(values, lengths, formats);
    Result result(PQexecParams(connection_, sql, params.size(), params.types(), values.data(),
                               lengths.data(), formats.data(), 1));
    check(result, doing);
    return result;
  }
  Result run(const char* sql, const std::string& doing) { return run(sql, Params(), doing); }
  // Several statements without parameters (a migration).
  void run_script(const char* sql, const std::string& doing) {
    Result result(PQexec(connection_, sql));
    check(result, doing);
  }

  void begin_if_needed() {
    if (in_transaction_) return;
    run("BEGIN", "starting a transaction");
    in_transaction_ = true;
  }
  void commit() {
    if (!in_transaction_) return;
    in_transaction_ = false;  // a failed COMMIT ends the transaction too
    run("COMMIT", "committing");
  }
  void roll_back() {
    if (!in_transaction_) return;
    in_transaction_ = false;
    PQclear(PQexec(connection_, "ROLLBACK"));
  }
  bool in_transaction() const { return in_transaction_; }

  // COPY table (columns) FROM STDIN in the binary format, the rows written by `rows` through
  // the CopyRows it is given.
  class CopyRows {
   public:
    explicit CopyRows(Connection& connection) : connection_(connection) {}
    void begin_row(std::int16_t fields) { put(big_endian(fields)); }
    void field(std::int64_t value) { sized(big_endian(value)); }
    void field(double value) { sized(big_endian(std::bit_cast<std::uint64_t>(value))); }
    void field(std::string_view text) { field_bytes(text.data(), text.size()); }
    void field(std::span<const std::uint8_t> bytes) {
      field_bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    }
    void flush(const std::string& doing) {
      if (buffer_.empty()) return;
      if (PQputCopyData(connection_.raw(), buffer_.data(), static_cast<int>(buffer_.size())) != 1)
        throw connection_.error(doing + " failed: " + trimmed(PQerrorMessage(connection_.raw())),
                                StorageProblem::unreachable);
      buffer_.clear();
    }
    std::size_t buffered() const { return buffer_.size(); }

   private:
    template <typename T>
    void put(T value) {
      buffer_.append(reinterpret_cast<const char*>(&value), sizeof value);
    }
    template <typename T>
    void sized(T value) {
      put(big_endian(std::int32_t{sizeof value}));
      put(value);
    }
    void field_bytes(const char* data, std::size_t size) {
      put(big_endian(static_cast<std::int32_t>(size)));
      buffer_.append(data, size);
    }
    Connection& connection_;
    std::string buffer_;
  };
  template <typename WriteRows>
  void copy_in(const char* copy_sql, const std::string& doing, WriteRows write_rows) {
    Result started(PQexec(connection_, copy_sql));
    if (PQresultStatus(started.raw()) != PGRES_COPY_IN) check(started, doing);
    CopyRows rows(*this);
    static constexpr char kHeader[] = "PGCOPY\n\377\r\n\0\0\0\0\0\0\0\0\0";
    PQputCopyData(connection_, kHeader, sizeof kHeader - 1);
    try {
      write_rows(rows);
      rows.flush(doing);
    } catch (...) {
      PQputCopyEnd(connection_, "the sender stopped");
      while (PGresult* r = PQgetResult(connection_)) PQclear(r);
      throw;
    }
    const std::int16_t trailer = big_endian(std::int16_t{-1});
    PQputCopyData(connection_, reinterpret_cast<const char*>(&trailer), sizeof trailer);
    if (PQputCopyEnd(connection_, nullptr) != 1)
      throw error(doing + " failed: " + trimmed(PQerrorMessage(connection_)),
                  StorageProblem::unreachable);
    Result finished(PQgetResult(connection_));
    check(finished, doing);
    while (PGresult* r = PQgetResult(connection_)) PQclear(r);
  }

 private:
  void check(const Result& result, const std::string& doing) {
    PGresult* raw = result.raw();
    const ExecStatusType status = PQresultStatus(raw);
    if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK) return;
    const char* state = raw ? PQresultErrorField(raw, PG_DIAG_SQLSTATE) : nullptr;
    const std::string sqlstate = state ? state : "";
    const std::string message =
        trimmed(raw && PQresultErrorMessage(raw)[0] ? PQresultErrorMessage(raw)
                                                    : PQerrorMessage(connection_));
    if (in_transaction_ && PQtransactionStatus(connection_) != PQTRANS_INTRANS) roll_back();
    if (sqlstate == "42501")  // insufficient_privilege, and row-level security's refusals
      throw AccessDenied("server " + server_name(settings_) + ": " + doing +
                         " was refused by the server (" + message + ")");
    StorageProblem problem = StorageProblem::other;
    if (PQstatus(connection_) == CONNECTION_BAD || sqlstate.starts_with("08") ||
        sqlstate.starts_with("57P"))
      problem = StorageProblem::unreachable;
    else if (sqlstate == "53100")
      problem = StorageProblem::disk_full;
    else if (sqlstate == "28000" || sqlstate == "28P01")
      problem = StorageProblem::refused;
    throw error(doing + " failed: " + message, problem);
  }

  ServerSettings settings_;
  PGconn* connection_ = nullptr;
  bool in_transaction_ = false;
};

namespace {

using Connection = PostgresSessionStore::Connection;

int read_schema_version(Connection& c) {
  Result exists = c.run("SELECT to_regclass('liversim_schema') IS NOT NULL", "reading the schema");
  if (exists.integer(0, 0) == 0) return 0;
  Result version =
      c.run("SELECT version::bigint FROM liversim_schema", "reading the schema version");
  return version.rows() == 1 ? static_cast<int>(version.integer(0, 0)) : 0;
}

std::int64_t person(Connection& c, std::string_view name, std::string_view role) {
  const std::string doing = "adding the " + std::string(role);
  c.run("INSERT INTO people (name, role) VALUES ($1, $2) ON CONFLICT (name, role) DO NOTHING",
        Params().add(name).add(role), doing);
  Result found = c.run("SELECT id FROM people WHERE name = $1 AND role = $2",
                       Params().add(name).add(role), "looking up the " + std::string(role));
  if (found.rows() != 1)
    throw c.error("the " + std::string(role) + " \"" + std::string(name) +
                  "\" is not on the server");
  return found.integer(0, 0);
}

std::int64_t scenario(Connection& c, std::string_view title, std::string_view text) {
  const std::string hash = sha256_hex(text);
  c.run(
      "INSERT INTO scenarios (sha256, title, content) VALUES ($1, $2, $3) "
      "ON CONFLICT (sha256) DO NOTHING",
      Params().add(std::string_view(hash)).add(title).add(text), "storing the scenario");
  Result found = c.run("SELECT id FROM scenarios WHERE sha256 = $1",
                       Params().add(std::string_view(hash)), "looking up the scenario");
  return found.integer(0, 0);
}

Params& add_mapping(Params& p, const std::optional<WorkspaceMapping>& mapping) {
  for (std::size_t k = 0; k < 8; ++k) {
    std::optional<double> value;
    if (mapping) value = stored_rows::mapping_values(*mapping)[k];
    p.add(value);
  }
  return p;
}

// The left hand's device and mapping (nulls for a one-handed session), as their columns are named
// in kLeftMappingColumns' order after left_device.
Params& add_left_hand(Params& p, const std::optional<LeftHandDevice>& left) {
  std::optional<std::string_view> device;
  std::optional<WorkspaceMapping> mapping;
  if (left) {
    device = left->device;
    mapping = left->mapping;
  }
  p.add(device);
  return add_mapping(p, mapping);
}

// "$first, ..., $last": a statement's parameters.
std::string placeholders(int first, int last) {
  std::string list;
  for (int k = first; k <= last; ++k) list += (k > first ? ", $" : "$") + std::to_string(k);
  return list;
}

Params& add_servo(Params& p, const std::optional<SessionServoFigures>& servo) {
  const auto count = [&](auto member) -> std::optional<std::int64_t> {
    if (!servo) return std::nullopt;
    return static_cast<std::int64_t>((*servo).*member);
  };
  const auto real = [&](auto member) -> std::optional<double> {
    if (!servo) return std::nullopt;
    return (*servo).*member;
  };
  using F = SessionServoFigures;
  p.add(count(&F::ticks))
      .add(real(&F::rate_hz))
      .add(real(&F::period_p50_ms))
      .add(real(&F::period_p99_ms))
      .add(real(&F::period_max_ms))
      .add(count(&F::missed_deadlines))
      .add(count(&F::force_clamps))
      .add(count(&F::stiffness_clamps))
      .add(count(&F::rate_limited))
      .add(count(&F::watchdog_trips))
      .add(count(&F::device_faults))
      .add(count(&F::dropped_frames));
  return p;
}

void store_replay(Connection& c, std::int64_t session, const ReplaySetup& replay) {
  const IntegratorSettings& i = replay.integrator;
  std::optional<std::int64_t> tets;
  if (replay.built_in_liver_tets) tets = *replay.built_in_liver_tets;
  c.run(
      "INSERT INTO session_replays (session_id, built_in_liver_tets, scenario_folder, "
      "integrator, step_s, tolerance_m, newton_tolerance_m, max_newton_iterations, loop_step_s) "
      "VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9)",
      Params()
          .add(session)
          .add(tets)
          .add(std::string_view(replay.scenario_folder))
          .add(integrator_name(i.kind))
          .add(i.step_s)
          .add(i.tolerance_m)
          .add(i.newton_tolerance_m)
          .add(std::int64_t{i.max_newton_iterations})
          .add(replay.loop_step_s),
      "storing how to replay the session");
}

void store_events(Connection& c, std::int64_t session, std::span<const SessionEvent> events) {
  for (const SessionEvent& event : events)
    c.run("INSERT INTO events (session_id, time_s, kind, detail, hand) VALUES ($1, $2, $3, $4, $5)",
          Params()
              .add(session)
              .add(event.time_s)
              .add(session_event_name(event.kind))
              .add(std::string_view(event.detail))
              .add(hand_name(event.hand)),
          "storing an event");
}

// Counts `count` more items (column "frame_count" or "input_count") to a session and returns the
// index of the first: one round trip, and the session named when there is none to add to.
std::int64_t claim_items(Connection& c, std::int64_t session, const char* count_column,
                         std::size_t count) {
  const std::string update = std::string("UPDATE sessions SET ") + count_column + " = " +
                             count_column + " + $2 WHERE id = $1 RETURNING " + count_column +
                             " - $2";
  Result first = c.run(update.c_str(), Params().add(session).add(static_cast<std::int64_t>(count)),
                       "counting the items of session " + std::to_string(session));
  if (first.rows() != 1)
    throw c.error("there is no session " + std::to_string(session) + " that this login records");
  return first.integer(0, 0);
}

// The password as the SCRAM-SHA-256 verifier the server keeps: the password itself is never sent.
std::string scram_verifier(Connection& c, std::string_view login, std::string_view password) {
  char* verifier = PQencryptPasswordConn(c.raw(), std::string(password).c_str(),
                                         std::string(login).c_str(), "scram-sha-256");
  if (verifier == nullptr)
    throw c.error("hashing the password failed: " + trimmed(PQerrorMessage(c.raw())));
  std::string scram(verifier);
  PQfreemem(verifier);
  return scram;
}

}  // namespace

PostgresSessionStore::PostgresSessionStore(const ServerSettings& settings,
                                           std::string_view password)
    : settings_(settings), connection_(std::make_unique<Connection>(settings, password)) {
  const int version = read_schema_version(*connection_);
  if (version == 0)
    throw connection_->error(
        "it holds no LiverSim schema; its administrator sets it up with `liversim-cli server "
        "set-up`",
        StorageProblem::not_a_database);
  if (version > kSchemaVersion)
    throw connection_->error("its schema was written by a newer LiverSim (version " +
                                 std::to_string(version) + "; this one reads up to " +
                                 std::to_string(kSchemaVersion) + ")",
                             StorageProblem::newer_version);
  if (version < kSchemaVersion)
    throw connection_->error("its schema is version " + std::to_string(version) +
                             "; its administrator migrates it to " +
                             std::to_string(kSchemaVersion) + " with `liversim-cli server set-up`");
}

PostgresSessionStore::~PostgresSessionStore() = default;

void PostgresSessionStore::set_up_server(const ServerSettings& administrator,
                                         std::string_view password, int version) {
  if (version < 1 || version > kSchemaVersion)
    throw std::invalid_argument("no server schema version " + std::to_string(version));
  Connection c(administrator, password);
  // One administrator at a time: a second waits here, then finds the schema done.
  c.begin_if_needed();
  c.run("SELECT pg_advisory_xact_lock(7413021)", "waiting for another set-up");
  for (const char* role : {"liversim_workstation", "liversim_instructor"}) {
    Result exists = c.run("SELECT count(*) FROM pg_roles WHERE rolname = $1",
                          Params().add(std::string_view(role)), "looking up the roles");
    if (exists.integer(0, 0) == 0)
      c.run_script(("CREATE ROLE " + std::string(role) + " NOLOGIN").c_str(),
                   std::string("creating the role ") + role);
  }
  for (int v = read_schema_version(c); v < version; ++v) {
    const std::string doing = "migrating the schema to version " + std::to_string(v + 1);
    for (const char* step : kServerMigrations[static_cast<std::size_t>(v)].steps)
      if (step) c.run_script(step, doing);
    c.run("UPDATE liversim_schema SET version = $1", Params().add(std::int64_t{v + 1}), doing);
  }
  c.commit();
}

void PostgresSessionStore::add_server_login(const ServerSettings& administrator,
                                            std::string_view administrator_password,
                                            std::string_view name, std::string_view password,
                                            ServerLoginKind kind) {
  if (name.empty()) throw std::invalid_argument("a server login needs a name");
  check_new_password(password);
  Connection c(administrator, administrator_password);
  const std::string scram = scram_verifier(c, name, password);
  if (kind == ServerLoginKind::instructor) {
    c.run("SELECT liversim_add_instructor($1, $2)", Params().add(name).add(std::string_view(scram)),
          "adding the instructor login");
    return;
  }
  // CREATE ROLE takes no parameters: the name is quoted by the server (format's %I), the
  // verifier as a literal (%L), inside a DO block that receives them bound.
  c.begin_if_needed();
  c.run(
      "SELECT set_config('liversim.new_login', $1, true), "
      "set_config('liversim.new_verifier', $2, true)",
      Params().add(name).add(std::string_view(scram)), "adding the workstation login");
  c.run_script(
      "DO $$ BEGIN EXECUTE format('CREATE ROLE %I LOGIN PASSWORD %L IN ROLE "
      "liversim_workstation', current_setting('liversim.new_login'), "
      "current_setting('liversim.new_verifier')); END $$",
      "adding the workstation login");
  c.commit();
}

bool PostgresSessionStore::connection_is_encrypted() const {
  return PQsslInUse(connection_->raw()) == 1;
}

int PostgresSessionStore::schema_version() {
  return read_schema_version(*connection_);
}

bool PostgresSessionStore::has_session(std::string_view uuid) {
  Result found = connection_->run("SELECT count(*) FROM sessions WHERE uuid = $1::text::uuid",
                                  Params().add(uuid), "looking up the session");
  return found.integer(0, 0) > 0;
}

bool PostgresSessionStore::receive_session(const SessionTransfer& session) {
  Connection& c = *connection_;
  if (c.in_transaction())
    throw std::logic_error("receive_session: the store has a session being written uncommitted");
  c.begin_if_needed();
  try {
    if (has_session(session.summary.uuid)) {
      c.roll_back();
      return false;
    }
    const SessionSummary& s = session.summary;
    const std::int64_t trainee = person(c, s.trainee, "trainee");
    const std::int64_t scenario_id = scenario(c, s.scenario_title, session.scenario_text);
    Params row;
    row.add(std::string_view(session.summary.uuid))
        .add(trainee)
        .add(scenario_id)
        .add(std::string_view(s.device))
        .add(s.started_unix_ms)
        .add(s.ended_unix_ms)
        .add(session_status_name(s.status))
        .add(s.frame_count)
        .add(session.input_count);
    add_servo(row, s.servo);
    add_mapping(row, s.mapping);
    add_left_hand(row, s.left_hand);
    row.add(s.left_frame_count);
    add_servo(row, s.left_servo);
    const std::string insert =
        std::string(
            "INSERT INTO sessions (uuid, trainee_id, scenario_id, device, "
            "started_unix_ms, ended_unix_ms, status, frame_count, input_count, ") +
        kServoColumns + ", " + kMappingColumns + ", left_device, " +
        stored_rows::kLeftMappingColumns + ", left_frame_count, " + stored_rows::kLeftServoColumns +
        ") VALUES ($1::text::uuid, " + placeholders(2, 51) +
        ") ON CONFLICT (uuid) DO NOTHING RETURNING id";
    Result added = c.run(insert.c_str(), row, "adding the session");
    if (added.rows() == 0) {  // another upload of it committed meanwhile
      c.roll_back();
      return false;
    }
    const std::int64_t id = added.integer(0, 0);
    if (session.replay) store_replay(c, id, *session.replay);
    store_events(c, id, session.events);
    for (const MetricValue& metric : session.metrics)
      c.run("INSERT INTO metrics (session_id, name, value) VALUES ($1, $2, $3)",
            Params().add(id).add(std::string_view(metric.name)).add(metric.value),
            "storing a metric");
    const auto copy_chunks = [&](const char* sql, const std::string& doing,
                                 const ChunkSource& source, bool timed) {
      if (!source) return;
      c.copy_in(sql, doing, [&](Connection::CopyRows& rows) {
        source([&](const StoredChunk& chunk) {
          rows.begin_row(static_cast<std::int16_t>(timed ? 7 : 5));
          rows.field(id);
          rows.field(chunk.first);
          rows.field(chunk.count);
          if (timed) {
            rows.field(chunk.first_time_s);
            rows.field(chunk.last_time_s);
          }
          rows.field(std::int64_t{chunk.layout});
          rows.field(std::span<const std::uint8_t>(chunk.data));
          if (rows.buffered() > (1u << 20)) rows.flush(doing);
        });
      });
    };
    copy_chunks(
        "COPY frame_chunks (session_id, first_frame, frame_count, first_time_s, "
        "last_time_s, layout, data) FROM STDIN (FORMAT binary)",
        "sending the frames", session.frame_chunks, true);
    copy_chunks(
        "COPY left_hand_frame_chunks (session_id, first_frame, frame_count, first_time_s, "
        "last_time_s, layout, data) FROM STDIN (FORMAT binary)",
        "sending the left hand's frames", session.left_frame_chunks, true);
    copy_chunks(
        "COPY input_chunks (session_id, first_input, input_count, layout, data) "
        "FROM STDIN (FORMAT binary)",
        "sending the simulation's input", session.input_chunks, false);
    c.commit();
    return true;
  } catch (...) {
    c.roll_back();
    throw;
  }
}

std::vector<SharedGrade> PostgresSessionStore::grades_of_sessions(
    std::span<const std::string> session_uuids) {
  std::vector<SharedGrade> result;
  for (const std::string& uuid : session_uuids) {
    Result rows = connection_->run(
        "SELECT g.uuid::text, p.name, g.graded_unix_ms, g.score, g.grade, g.comment "
        "FROM grades g JOIN people p ON p.id = g.instructor_id "
        "JOIN sessions s ON s.id = g.session_id WHERE s.uuid = $1::text::uuid ORDER BY g.id",
        Params().add(std::string_view(uuid)), "reading grades");
    for (int r = 0; r < rows.rows(); ++r) {
      SharedGrade shared;
      shared.session_uuid = uuid;
      shared.grade_uuid = rows.text(r, 0);
      shared.grade = stored_rows::session_grade(rows.row(r), 1);
      result.push_back(std::move(shared));
    }
  }
  return result;
}

void PostgresSessionStore::publish_scenario(const Instructor& by, std::string_view name,
                                            std::string_view text) {
  Connection& c = connection_of(by);
  // Workstations run what they pull: only a scenario that reads and validates goes out.
  const ScenarioReading reading = read_scenario(text);
  if (!reading.scenario) {
    std::string errors;
    for (const ScenarioError& e : reading.errors) errors += (errors.empty() ? "" : "; ") + e.text();
    throw std::invalid_argument("the scenario \"" + std::string(name) +
                                "\" was not published: " + errors);
  }
  const std::string hash = sha256_hex(text);
  c.run(
      "INSERT INTO published_scenarios (name, title, content, sha256, published_unix_ms) "
      "VALUES ($1, $2, $3, $4, $5) ON CONFLICT (name) DO UPDATE SET title = EXCLUDED.title, "
      "content = EXCLUDED.content, sha256 = EXCLUDED.sha256, "
      "version = published_scenarios.version + 1, published_by = session_user, "
      "published_unix_ms = EXCLUDED.published_unix_ms",
      Params()
          .add(name)
          .add(std::string_view(reading.scenario->title))
          .add(text)
          .add(std::string_view(hash))
          .add(stored_rows::unix_ms_now()),
      "publishing the scenario \"" + std::string(name) + "\"");
}

std::vector<PublishedScenario> PostgresSessionStore::published_scenarios() {
  Result rows = connection_->run(
      "SELECT name, title, content, sha256, version, published_by, published_unix_ms "
      "FROM published_scenarios ORDER BY name",
      "reading the published scenarios");
  std::vector<PublishedScenario> result;
  for (int r = 0; r < rows.rows(); ++r)
    result.push_back({rows.text(r, 0), rows.text(r, 1), rows.text(r, 2), rows.text(r, 3),
                      rows.integer(r, 4), rows.text(r, 5), rows.integer(r, 6)});
  return result;
}

std::int64_t PostgresSessionStore::begin_session(const SessionStart& start) {
  Connection& c = *connection_;
  c.begin_if_needed();
  const std::int64_t trainee = person(c, start.trainee, "trainee");
  const std::int64_t scenario_id = scenario(c, start.scenario_title, start.scenario_text);
  Params row;
  row.add(std::string_view(new_uuid()))
      .add(trainee)
      .add(scenario_id)
      .add(std::string_view(start.device))
      .add(start.started_unix_ms);
  add_mapping(row, start.mapping);
  add_left_hand(row, start.left_hand);
  const std::string insert = std::string(
                                 "INSERT INTO sessions (uuid, trainee_id, scenario_id, "
                                 "device, started_unix_ms, status, ") +
                             kMappingColumns + ", left_device, " +
                             stored_rows::kLeftMappingColumns +
                             ") VALUES ($1::text::uuid, $2, $3, $4, $5, 'recording', " +
                             placeholders(6, 22) + ") RETURNING id";
  const std::int64_t id = c.run(insert.c_str(), row, "adding the session").integer(0, 0);
  if (start.replay) store_replay(c, id, *start.replay);
  c.commit();
  return id;
}

void PostgresSessionStore::append_frames(std::int64_t session, Hand hand,
                                         std::span<const ServoFrame> frames) {
  if (frames.empty()) return;
  Connection& c = *connection_;
  c.begin_if_needed();
  const bool left = hand == Hand::left;
  if (left && c.run("SELECT 1 FROM sessions WHERE id = $1 AND left_device IS NOT NULL",
                    Params().add(session), "looking up session " + std::to_string(session))
                      .rows() != 1)
    throw c.error("session " + std::to_string(session) +
                  " was begun without a left-hand device: it takes no left-hand frames");
  const std::vector<std::uint8_t> bytes = encode_frame_chunk(frames);
  c.run(left ? "INSERT INTO left_hand_frame_chunks (session_id, first_frame, frame_count, "
               "first_time_s, last_time_s, layout, data) VALUES ($1, $2, $3, $4, $5, $6, $7)"
             : "INSERT INTO frame_chunks (session_id, first_frame, frame_count, first_time_s, "
               "last_time_s, layout, data) VALUES ($1, $2, $3, $4, $5, $6, $7)",
        Params()
            .add(session)
            .add(claim_items(c, session, left ? "left_frame_count" : "frame_count", frames.size()))
            .add(static_cast<std::int64_t>(frames.size()))
            .add(frames.front().time_s)
            .add(frames.back().time_s)
            .add(std::int64_t{kFrameChunkLayout})
            .add(std::span<const std::uint8_t>(bytes)),
        "storing frames");
}

void PostgresSessionStore::append_events(std::int64_t session,
                                         std::span<const SessionEvent> events) {
  if (events.empty()) return;
  connection_->begin_if_needed();
  store_events(*connection_, session, events);
}

void PostgresSessionStore::append_inputs(std::int64_t session,
                                         std::span<const SimulationInput> inputs) {
  if (inputs.empty()) return;
  Connection& c = *connection_;
  c.begin_if_needed();
  const std::vector<std::uint8_t> bytes = encode_input_chunk(inputs);
  c.run(
      "INSERT INTO input_chunks (session_id, first_input, input_count, layout, data) "
      "VALUES ($1, $2, $3, $4, $5)",
      Params()
          .add(session)
          .add(claim_items(c, session, "input_count", inputs.size()))
          .add(static_cast<std::int64_t>(inputs.size()))
          .add(std::int64_t{kInputChunkLayout})
          .add(std::span<const std::uint8_t>(bytes)),
      "storing the simulation's input");
}

void PostgresSessionStore::commit() {
  connection_->commit();
}

void PostgresSessionStore::end_session(std::int64_t session, std::int64_t ended_unix_ms,
                                       const SessionServoFigures& servo,
                                       const std::optional<SessionServoFigures>& left_servo) {
  Connection& c = *connection_;
  c.begin_if_needed();
  // The left hand's figures first: once complete, the row is no longer the workstation's to
  // update (the policy only_while_recording).
  if (left_servo) {
    Params left_row;
    left_row.add(session);
    add_servo(left_row, left_servo);
    Result left = c.run(
        ("UPDATE sessions SET (" + stored_rows::kLeftServoColumns + ") = (" + placeholders(2, 13) +
         ") WHERE id = $1 AND left_device IS NOT NULL " + "RETURNING id")
            .c_str(),
        left_row, "ending the session's left hand");
    if (left.rows() != 1) {
      c.roll_back();
      throw c.error("session " + std::to_string(session) +
                    " has no left-hand device that this login records");
    }
  }
  Params row;
  row.add(session).add(ended_unix_ms);
  add_servo(row, servo);
  Result ended = c.run(
      "UPDATE sessions SET status = 'complete', ended_unix_ms = $2, servo_ticks = $3, "
      "servo_rate_hz = $4, servo_period_p50_ms = $5, servo_period_p99_ms = $6, "
      "servo_period_max_ms = $7, missed_deadlines = $8, force_clamps = $9, "
      "stiffness_clamps = $10, rate_limited = $11, watchdog_trips = $12, device_faults = $13, "
      "dropped_frames = $14 WHERE id = $1 RETURNING id",
      row, "ending the session");
  if (ended.rows() != 1) {
    c.roll_back();
    throw c.error("there is no session " + std::to_string(session) + " that this login records");
  }
  c.commit();
}

void PostgresSessionStore::store_metrics(std::int64_t session,
                                         std::span<const MetricValue> metrics) {
  Connection& c = *connection_;
  c.begin_if_needed();
  for (const MetricValue& metric : metrics)
    c.run(
        "INSERT INTO metrics (session_id, name, value) VALUES ($1, $2, $3) "
        "ON CONFLICT (session_id, name) DO UPDATE SET value = EXCLUDED.value",
        Params().add(session).add(std::string_view(metric.name)).add(metric.value),
        "storing a metric");
  c.commit();
}

std::vector<MetricValue> PostgresSessionStore::metrics(std::int64_t session) {
  Result rows =
      connection_->run("SELECT name, value FROM metrics WHERE session_id = $1 ORDER BY name",
                       Params().add(session), "reading metrics");
  std::vector<MetricValue> result;
  for (int r = 0; r < rows.rows(); ++r) result.push_back({rows.text(r, 0), rows.real(r, 1)});
  return result;
}

PostgresSessionStore::Connection& PostgresSessionStore::connection_of(
    const Instructor& instructor) {
  const auto found = instructors_.find(instructor.id());
  if (found == instructors_.end() || found->second->settings().user != instructor.name())
    throw AccessDenied("\"" + instructor.name() + "\" has not logged in to the server " +
                       server_name(settings_));
  return *found->second;
}

Instructor PostgresSessionStore::add_instructor_account(std::string_view name,
                                                        std::string_view password,
                                                        const Instructor* added_by) {
  if (name.empty()) throw std::invalid_argument("an instructor account needs a name");
  check_new_password(password);
  if (added_by == nullptr)
    throw AccessDenied(
        "on the training centre's server, instructor accounts are added by an instructor who "
        "has logged in, or by its administrator (liversim-cli server add-login)");
  Connection& c = connection_of(*added_by);
  const std::string scram = scram_verifier(c, name, password);
  const std::int64_t id = c.run("SELECT liversim_add_instructor($1, $2)",
                                Params().add(name).add(std::string_view(scram)),
                                "adding the instructor account \"" + std::string(name) + "\"")
                              .integer(0, 0);
  return vouch_for(id, std::string(name));
}

bool PostgresSessionStore::has_instructor_accounts() {
  Result count = connection_->run(
      "SELECT count(*) FROM pg_auth_members m JOIN pg_roles g ON g.oid = m.roleid "
      "WHERE g.rolname = 'liversim_instructor'",
      "counting instructor accounts");
  return count.integer(0, 0) > 0;
}

std::optional<Instructor> PostgresSessionStore::log_in_instructor(std::string_view name,
                                                                  std::string_view password) {
  if (name.empty() || password.empty()) return std::nullopt;
  ServerSettings as_instructor = settings_;
  as_instructor.user = std::string(name);
  std::unique_ptr<Connection> c;
  try {
    c = std::make_unique<Connection>(as_instructor, password);
  } catch (const StorageError& e) {
    if (e.problem() == StorageProblem::refused) return std::nullopt;
    throw;
  }
  Result found = c->run(
      "SELECT p.id FROM people p WHERE p.name = session_user AND p.role = 'instructor' "
      "AND pg_has_role(session_user, 'liversim_instructor', 'MEMBER')",
      "checking the instructor");
  if (found.rows() != 1) return std::nullopt;  // a login, but not an instructor's
  const std::int64_t id = found.integer(0, 0);
  instructors_[id] = std::move(c);
  return vouch_for(id, std::string(name));
}

void PostgresSessionStore::store_grade(const Instructor& by, std::int64_t session,
                                       const SessionGrade& grade) {
  Connection& c = connection_of(by);
  c.run(
      "INSERT INTO grades (session_id, instructor_id, graded_unix_ms, score, grade, comment) "
      "VALUES ($1, $2, $3, $4, $5, $6)",
      Params()
          .add(session)
          .add(by.id())
          .add(grade.graded_unix_ms)
          .add(grade.score_percent)
          .add(std::string_view(grade.grade))
          .add(std::string_view(grade.comment)),
      "storing a grade");
}

std::vector<SessionGrade> PostgresSessionStore::grades(std::int64_t session) {
  Result rows = connection_->run(
      "SELECT p.name, g.graded_unix_ms, g.score, g.grade, g.comment FROM grades g "
      "JOIN people p ON p.id = g.instructor_id WHERE g.session_id = $1 ORDER BY g.id",
      Params().add(session), "reading grades");
  std::vector<SessionGrade> result;
  for (int r = 0; r < rows.rows(); ++r) result.push_back(stored_rows::session_grade(rows.row(r)));
  return result;
}

std::vector<SessionSummary> PostgresSessionStore::sessions() {
  return list_sessions(std::nullopt);
}

std::vector<SessionSummary> PostgresSessionStore::sessions_of_trainee(std::string_view trainee) {
  return list_sessions(trainee);
}

std::vector<SessionSummary> PostgresSessionStore::list_sessions(
    std::optional<std::string_view> trainee) {
  static const std::string query =
      stored_rows::kSessionSummarySelect + "WHERE $1::text IS NULL OR p.name = $1 ORDER BY s.id";
  Result rows = connection_->run(query.c_str(), Params().add(trainee), "listing sessions");
  std::vector<SessionSummary> result;
  for (int r = 0; r < rows.rows(); ++r) result.push_back(stored_rows::session_summary(rows.row(r)));
  return result;
}

namespace {

// The session's chunks, in order, decoded and joined; a gap or a layout this version cannot read
// is named (as the embedded store does).
template <typename Item, typename Decode>
std::vector<Item> joined_chunks(Connection& c, const char* sql, std::int64_t session,
                                const std::string& items, int layout, Decode decode,
                                const ReadingProgress& progress = {}, std::size_t total = 0) {
  std::vector<Item> result;
  const auto report = [&] {
    if (progress && !progress(result.size(), total)) throw ReadingCancelled();
  };
  report();
  // In slices of 200 chunks, so that a long session is never one answer in memory twice.
  std::int64_t next = 0;
  for (;;) {
    Result rows = c.run(sql, Params().add(session).add(next), "reading " + items);
    if (rows.rows() == 0) break;
    for (int r = 0; r < rows.rows(); ++r) {
      try {
        stored_rows::append_chunk(result, rows.integer(r, 0), rows.integer(r, 1), layout,
                                  rows.bytes(r, 2), items, decode);
      } catch (const StorageError& e) {
        throw c.error("session " + std::to_string(session) + ": " + e.what(),
                      e.problem() == StorageProblem::other ? StorageProblem::damaged : e.problem());
      }
      report();
    }
    next = static_cast<std::int64_t>(result.size());
  }
  return result;
}

}  // namespace

std::vector<ServoFrame> PostgresSessionStore::frames(std::int64_t session, Hand hand,
                                                     const ReadingProgress& progress) {
  const bool left = hand == Hand::left;
  std::size_t total = 0;
  if (progress)
    total = static_cast<std::size_t>(
        connection_
            ->run(left ? "SELECT COALESCE(SUM(frame_count), 0)::bigint FROM "
                         "left_hand_frame_chunks WHERE session_id = $1"
                       : "SELECT COALESCE(SUM(frame_count), 0)::bigint FROM frame_chunks "
                         "WHERE session_id = $1",
                  Params().add(session), "counting frames")
            .integer(0, 0));
  return joined_chunks<ServoFrame>(*connection_,
                                   left ? "SELECT first_frame, layout, data FROM "
                                          "left_hand_frame_chunks WHERE session_id = $1 AND "
                                          "first_frame >= $2 ORDER BY first_frame LIMIT 200"
                                        : "SELECT first_frame, layout, data FROM frame_chunks "
                                          "WHERE session_id = $1 AND first_frame >= $2 "
                                          "ORDER BY first_frame LIMIT 200",
                                   session, left ? "left-hand frames" : "frames", kFrameChunkLayout,
                                   decode_frame_chunk, progress, total);
}

std::vector<SimulationInput> PostgresSessionStore::inputs(std::int64_t session) {
  return joined_chunks<SimulationInput>(*connection_,
                                        "SELECT first_input, layout, data FROM input_chunks "
                                        "WHERE session_id = $1 AND first_input >= $2 "
                                        "ORDER BY first_input LIMIT 200",
                                        session, "inputs", kInputChunkLayout, decode_input_chunk);
}

std::vector<SessionEvent> PostgresSessionStore::events(std::int64_t session) {
  Result rows = connection_->run(
      "SELECT time_s, kind, detail, hand FROM events WHERE session_id = $1 ORDER BY time_s, id",
      Params().add(session), "reading events");
  std::vector<SessionEvent> result;
  for (int r = 0; r < rows.rows(); ++r) {
    try {
      result.push_back(stored_rows::session_event(rows.real(r, 0), rows.text(r, 1), rows.text(r, 2),
                                                  rows.text(r, 3)));
    } catch (const StorageError& e) {
      throw connection_->error("session " + std::to_string(session) + " " + e.what());
    }
  }
  return result;
}

std::string PostgresSessionStore::scenario_text(std::int64_t session) {
  Result row = connection_->run(
      "SELECT c.content FROM sessions s JOIN scenarios c ON c.id = s.scenario_id WHERE s.id = $1",
      Params().add(session), "reading the scenario");
  if (row.rows() != 1) throw connection_->error("there is no session " + std::to_string(session));
  return row.text(0, 0);
}

std::optional<ReplaySetup> PostgresSessionStore::replay_setup(std::int64_t session) {
  Result row = connection_->run(
      "SELECT built_in_liver_tets, scenario_folder, integrator, step_s, tolerance_m, "
      "newton_tolerance_m, max_newton_iterations, loop_step_s FROM session_replays "
      "WHERE session_id = $1",
      Params().add(session), "reading how to replay the session");
  if (row.rows() != 1) return std::nullopt;
  ReplaySetup setup;
  if (!row.is_null(0, 0)) setup.built_in_liver_tets = static_cast<int>(row.integer(0, 0));
  setup.scenario_folder = row.text(0, 1);
  const std::string integrator = row.text(0, 2);
  const std::optional<IntegratorKind> kind = integrator_from_name(integrator);
  if (!kind)
    throw connection_->error("session " + std::to_string(session) +
                             " was run with the integrator \"" + integrator +
                             "\", which this version does not know");
  setup.integrator.kind = *kind;
  setup.integrator.step_s = row.real(0, 3);
  setup.integrator.tolerance_m = row.real(0, 4);
  setup.integrator.newton_tolerance_m = row.real(0, 5);
  setup.integrator.max_newton_iterations = static_cast<int>(row.integer(0, 6));
  if (!row.is_null(0, 7)) setup.loop_step_s = row.real(0, 7);
  return setup;
}

}  // namespace liversim
