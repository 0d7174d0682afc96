// The training centre against a real PostgreSQL server (a throwaway cluster on loopback): the
// schema and its migration, uploads exactly once, an upload cut by the server stopping, grades
// and scenarios shared, the roles enforced by the server as well as by the application, and TLS.
#include "liversim/engine/integrator.h"
#include "liversim/storage/postgres_session_store.h"
#include "liversim/storage/session_upload.h"
#include "liversim/storage/sqlite_session_store.h"
#include "liversim/storage/training_centre_sync.h"
#include "recorded_session.h"
#include "storage_test_support.h"
#include "throwaway_postgres.h"

#include <gtest/gtest.h>
#include <libpq-fe.h>
#include <sqlite3.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

namespace liversim {
namespace {

namespace fs = std::filesystem;
using testing::expect_same_frames;
using testing::record_session;
using testing::Recorded;
using testing::synthetic_frames;
using testing::ThrowawayPostgres;

constexpr const char* kWorkstationPassword = "workstation password 1";
constexpr const char* kOtherWorkstationPassword = "workstation password 2";
constexpr const char* kInstructorPassword = "instructor password A";
constexpr const char* kOtherInstructorPassword = "instructor password B";

fs::path fresh_database(const std::string& name) {
  return testing::fresh_database(name, "training-centre");
}

// Runs SQL as a login, outside LiverSim: what someone who bypasses the application can do.
// Returns "" when the server did it, or its error message.
std::string run_sql_as(const ServerSettings& login, const std::string& password,
                       const std::string& sql) {
  const std::string port = std::to_string(login.port);
  const char* keys[] = {"host", "port", "dbname", "user", "password", "sslmode", nullptr};
  const char* values[] = {login.host.c_str(),
                          port.c_str(),
                          login.database.c_str(),
                          login.user.c_str(),
                          password.c_str(),
                          "disable",
                          nullptr};
  PGconn* c = PQconnectdbParams(keys, values, 0);
  std::string error;
  if (PQstatus(c) != CONNECTION_OK) {
    error = PQerrorMessage(c);
  } else {
    PGresult* r = PQexec(c, sql.c_str());
    const ExecStatusType status = PQresultStatus(r);
    if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK) error = PQresultErrorMessage(r);
    PQclear(r);
  }
  PQfinish(c);
  return error;
}

// The rows of a table (or "table WHERE ..."), counted by the administrator.
std::int64_t count_rows(const ThrowawayPostgres& server, const std::string& table) {
  const ServerSettings admin = server.administrator();
  const std::string port = std::to_string(admin.port);
  const char* keys[] = {"host", "port", "dbname", "user", "password", "sslmode", nullptr};
  const char* values[] = {admin.host.c_str(),
                          port.c_str(),
                          "liversim",
                          "liversim_admin",
                          ThrowawayPostgres::kAdministratorPassword,
                          "disable",
                          nullptr};
  PGconn* c = PQconnectdbParams(keys, values, 0);
  PGresult* r = PQexec(c, ("SELECT count(*) FROM " + table).c_str());
  const std::int64_t count =
      PQresultStatus(r) == PGRES_TUPLES_OK ? std::atoll(PQgetvalue(r, 0, 0)) : -1;
  PQclear(r);
  PQfinish(c);
  return count;
}

// A server set up as a centre: the schema, two workstations' logins and two instructors'.
class TrainingCentre : public ::testing::Test {
 protected:
  void SetUp() override {
    server_ = std::make_unique<ThrowawayPostgres>();
    const ServerSettings admin = server_->administrator();
    const char* admin_password = ThrowawayPostgres::kAdministratorPassword;
    PostgresSessionStore::set_up_server(admin, admin_password);
    PostgresSessionStore::add_server_login(admin, admin_password, "ws-01", kWorkstationPassword,
                                           ServerLoginKind::workstation);
    PostgresSessionStore::add_server_login(admin, admin_password, "ws-02",
                                           kOtherWorkstationPassword, ServerLoginKind::workstation);
    PostgresSessionStore::add_server_login(admin, admin_password, "Dr. Grey", kInstructorPassword,
                                           ServerLoginKind::instructor);
    PostgresSessionStore::add_server_login(admin, admin_password, "Dr. O'Neil",
                                           kOtherInstructorPassword, ServerLoginKind::instructor);
  }
  ServerSettings workstation() const { return server_->as("ws-01"); }
  std::unique_ptr<ThrowawayPostgres> server_;
};

TEST(ServerUrl, ReadsBackWhatItWritesAndRefusesPasswordsAndNonsense) {
  const ServerSettings s = parse_server_url(
      "postgresql://ws-01@db.hospital.example:6432/training?sslmode=verify-full&"
      "sslrootcert=/etc/liversim/ca.crt&connect_timeout=7");
  EXPECT_EQ(s.user, "ws-01");
  EXPECT_EQ(s.host, "db.hospital.example");
  EXPECT_EQ(s.port, 6432);
  EXPECT_EQ(s.database, "training");
  EXPECT_EQ(s.ssl_mode, "verify-full");
  EXPECT_EQ(s.ssl_root_cert, "/etc/liversim/ca.crt");
  EXPECT_EQ(s.connect_timeout_s, 7);
  EXPECT_EQ(parse_server_url(server_url(s)), s);
  ServerSettings odd;
  odd.host = "::1";
  odd.user = "Dr. O'Neil & co";
  odd.database = "a b";
  odd.ssl_cert = "/home/x y/client.crt";
  EXPECT_EQ(parse_server_url(server_url(odd)), odd) << server_url(odd);
  for (const char* bad :
       {"postgresql://ws:secret@db/liversim", "postgresql://db/liversim?password=secret",
        "mysql://db/x", "postgresql://db:99999/x", "postgresql://db/x?sslmode=maybe",
        "postgresql://db/x?colour=blue", "postgresql:///x"}) {
    SCOPED_TRACE(bad);
    EXPECT_THROW(parse_server_url(bad), std::invalid_argument);
  }
  for (const char* with_password :
       {"postgresql://ws:secret@db/liversim", "postgresql://db/liversim?password=secret&x=1"}) {
    try {
      parse_server_url(with_password);
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("password"), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find("secret"), std::string::npos)
          << "the message repeats the password: " << e.what();
    }
  }
}

TEST_F(TrainingCentre, AFinishedSessionIsUploadedExactlyOnceWithEveryBit) {
  SqliteSessionStore local(fresh_database("upload"));
  const Recorded a = record_session(local, "Trainee A", 1000, 1);
  // With a device in each hand: the left hand's frames, mapping, figures and events go too.
  const Recorded b = record_session(local, "Trainee B", 333, 2, 222);
  PostgresSessionStore central(workstation(), kWorkstationPassword);

  const SyncReport first = synchronise(local, central);
  EXPECT_FALSE(first.problem) << *first.problem;
  EXPECT_EQ(first.uploaded, 2);
  EXPECT_EQ(first.already_there, 0);
  EXPECT_GT(first.chunk_bytes_sent, 1333 * 80);

  const std::vector<SessionSummary> here = local.sessions();
  const std::vector<SessionSummary> there = central.sessions();
  ASSERT_EQ(there.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    SCOPED_TRACE(k);
    const Recorded& r = k == 0 ? a : b;
    EXPECT_EQ(there[k].uuid, here[k].uuid);
    EXPECT_EQ(there[k].trainee, here[k].trainee);
    EXPECT_EQ(there[k].status, SessionStatus::complete);
    EXPECT_EQ(there[k].frame_count, static_cast<std::int64_t>(r.frames.size()));
    EXPECT_EQ(there[k].servo, here[k].servo);
    ASSERT_TRUE(there[k].mapping);
    EXPECT_EQ(there[k].mapping->scale, 1.25);
    expect_same_frames(central.frames(there[k].id), r.frames);
    EXPECT_EQ(there[k].left_hand.has_value(), !r.left_frames.empty());
    EXPECT_EQ(there[k].left_frame_count, static_cast<std::int64_t>(r.left_frames.size()));
    EXPECT_EQ(there[k].left_servo, r.left_servo);
    if (there[k].left_hand) {
      EXPECT_EQ(there[k].left_hand->device, "Scripted left");
      EXPECT_EQ(there[k].left_hand->mapping.scale, 2.0);
      EXPECT_EQ(there[k].left_hand->mapping.offset_m, Eigen::Vector3d(-0.05, 0.0, 0.01));
    }
    expect_same_frames(central.frames(there[k].id, Hand::left), r.left_frames);
    EXPECT_EQ(central.inputs(there[k].id).size(), r.inputs.size());
    EXPECT_EQ(central.inputs(there[k].id).back().servo_time_s, r.inputs.back().servo_time_s);
    EXPECT_EQ(central.events(there[k].id), r.events);
    EXPECT_EQ(central.metrics(there[k].id), r.metrics);
    EXPECT_EQ(central.scenario_text(there[k].id), local.scenario_text(r.id));
    const std::optional<ReplaySetup> replay = central.replay_setup(there[k].id);
    ASSERT_TRUE(replay);
    EXPECT_EQ(replay->integrator.kind, IntegratorKind::dopri5);
    EXPECT_EQ(replay->integrator.tolerance_m, 2e-7);
    EXPECT_TRUE(local.upload_state(r.id, server_name(central.settings())).uploaded_unix_ms);
  }

  // Again: nothing left to send.
  const SyncReport again = synchronise(local, central);
  EXPECT_EQ(again.uploaded + again.already_there, 0);

  // The note of the upload lost (a workstation killed between the server's commit and its own):
  // the next run sends the sessions again, and the server keeps one copy.
  const std::int64_t chunks = count_rows(*server_, "frame_chunks");
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(local.file().c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, "DELETE FROM session_uploads", nullptr, nullptr, nullptr),
              SQLITE_OK);
    sqlite3_close(db);
  }
  const SyncReport duplicate = synchronise(local, central);
  EXPECT_EQ(duplicate.uploaded, 0);
  EXPECT_EQ(duplicate.already_there, 2);
  EXPECT_EQ(central.sessions().size(), 2u);
  EXPECT_EQ(count_rows(*server_, "sessions"), 2);
  EXPECT_EQ(count_rows(*server_, "frame_chunks"), chunks);
  EXPECT_EQ(count_rows(*server_, "left_hand_frame_chunks"), 6);  // 222 frames by 40
  EXPECT_EQ(count_rows(*server_, "events"), 6);
  EXPECT_EQ(count_rows(*server_, "metrics"), 4);
}

TEST_F(TrainingCentre, ASessionStillRecordingIsNotUploaded) {
  SqliteSessionStore local(fresh_database("recording"));
  SessionStart start{"Trainee A",       "Palpation",  "{}",        "Scripted",
                     1'795'000'000'000, std::nullopt, std::nullopt};
  const std::int64_t id = local.begin_session(start);
  const std::vector<ServoFrame> frames = synthetic_frames(10, 3);
  local.append_frames(id, frames);
  local.commit();
  PostgresSessionStore central(workstation(), kWorkstationPassword);
  EXPECT_EQ(synchronise(local, central).uploaded, 0);
  EXPECT_TRUE(central.sessions().empty());
  local.end_session(id, 1'795'000'001'000, {});
  EXPECT_EQ(synchronise(local, central).uploaded, 1);
}

// The server stops (as a crash or a cut cable does) half-way through sending a session's frames:
// the upload fails with the server named, the server keeps nothing of it (one transaction), and
// once the server is back the next run uploads it whole, once.
TEST_F(TrainingCentre, AServerStoppedMidUploadKeepsNothingHalfAndTheNextRunUploadsItWhole) {
  SqliteSessionStore local(fresh_database("stopped"));
  const Recorded r = record_session(local, "Trainee A", 20'000, 4);  // 400 chunks
  {
    PostgresSessionStore central(workstation(), kWorkstationPassword);
    SessionTransfer transfer = local.transfer_of(r.id);
    int sent = 0;
    transfer.frame_chunks = [&, inner = transfer.frame_chunks](const ChunkSink& sink) {
      inner([&](const StoredChunk& chunk) {
        if (++sent == 200) server_->stop();
        sink(chunk);
      });
    };
    try {
      central.receive_session(transfer);
      ADD_FAILURE() << "the upload went through with the server stopped";
    } catch (const StorageError& e) {
      EXPECT_EQ(e.problem(), StorageProblem::unreachable) << e.what();
      EXPECT_NE(std::string(e.what()).find(server_name(workstation())), std::string::npos)
          << e.what();
    }
    EXPECT_GE(sent, 200);
  }
  // While it is down, a run reports the problem and notes it on the session.
  try {
    PostgresSessionStore central(workstation(), kWorkstationPassword);
    ADD_FAILURE() << "connected to a stopped server";
  } catch (const StorageError& e) {
    EXPECT_EQ(e.problem(), StorageProblem::unreachable) << e.what();
  }
  server_->start();
  EXPECT_EQ(count_rows(*server_, "sessions"), 0);
  EXPECT_EQ(count_rows(*server_, "frame_chunks"), 0);

  PostgresSessionStore central(workstation(), kWorkstationPassword);
  const SyncReport report = synchronise(local, central);
  EXPECT_FALSE(report.problem) << *report.problem;
  EXPECT_EQ(report.uploaded, 1);
  ASSERT_EQ(central.sessions().size(), 1u);
  expect_same_frames(central.frames(central.sessions()[0].id), r.frames);
  EXPECT_EQ(synchronise(local, central).uploaded, 0);
}

// A run that meets a failure mid-way notes it on that session and leaves the rest for the next.
TEST_F(TrainingCentre, AFailedUploadIsNotedOnTheSessionAndRetried) {
  SqliteSessionStore local(fresh_database("retried"));
  const Recorded r = record_session(local, "Trainee A", 100, 5);
  record_session(local, "Trainee B", 100, 6);
  PostgresSessionStore central(workstation(), kWorkstationPassword);
  server_->stop();
  const SyncReport failed = synchronise(local, central);
  ASSERT_TRUE(failed.problem);
  EXPECT_EQ(failed.uploaded, 0);
  EXPECT_EQ(failed.waiting, 2);
  const auto state = local.upload_state(r.id, server_name(central.settings()));
  EXPECT_FALSE(state.uploaded_unix_ms);
  EXPECT_EQ(state.attempts, 1);
  EXPECT_FALSE(state.last_problem.empty());
  server_->start();
  PostgresSessionStore reconnected(workstation(), kWorkstationPassword);
  const SyncReport retried = synchronise(local, reconnected);
  EXPECT_FALSE(retried.problem) << *retried.problem;
  EXPECT_EQ(retried.uploaded, 2);
  EXPECT_EQ(local.upload_state(r.id, server_name(central.settings())).attempts, 2);
}

// A grade entered at the centre (an instructor's office, or any workstation where the
// instructor logs in to the server) reaches the workstation whose trainee did the session, once.
TEST_F(TrainingCentre, GradesEnteredAnywhereAreVisibleEverywhere) {
  SqliteSessionStore local(fresh_database("grades"));
  const Recorded r = record_session(local, "Trainee A", 100, 7);
  PostgresSessionStore central(workstation(), kWorkstationPassword);
  synchronise(local, central);

  PostgresSessionStore office(server_->as("Dr. Grey"), kInstructorPassword);
  const std::optional<Instructor> grey = office.log_in_instructor("Dr. Grey", kInstructorPassword);
  ASSERT_TRUE(grey);
  const std::int64_t on_server = office.sessions().at(0).id;
  const SessionGrade grade{"Dr. Grey", 1'795'000'200'000, 82.5, "pass",
                           "Clean margin; O'Neil's \"technique\" -- ; DROP TABLE grades;"};
  office.store_grade(*grey, on_server, grade);
  EXPECT_EQ(office.grades(on_server), std::vector<SessionGrade>{grade});

  // Another workstation where an instructor logs in sees it, and adds one.
  PostgresSessionStore elsewhere(server_->as("ws-02"), kOtherWorkstationPassword);
  EXPECT_EQ(elsewhere.grades(on_server), std::vector<SessionGrade>{grade});
  const std::optional<Instructor> oneil =
      elsewhere.log_in_instructor("Dr. O'Neil", kOtherInstructorPassword);
  ASSERT_TRUE(oneil);
  SessionGrade second{"Dr. O'Neil", 1'795'000'300'000, std::nullopt, "B+", "agreed"};
  elsewhere.store_grade(*oneil, on_server, second);

  const SyncReport pulled = synchronise(local, central);
  EXPECT_EQ(pulled.grades_pulled, 2);
  EXPECT_EQ(local.grades(r.id), (std::vector<SessionGrade>{grade, second}));
  EXPECT_EQ(synchronise(local, central).grades_pulled, 0);
  EXPECT_EQ(local.grades(r.id).size(), 2u);
}

// What a workstation's login and an instructor's may not do, refused by the server itself when
// the application is bypassed (plain SQL with the login's password), and by the application.
TEST_F(TrainingCentre, TheServerEnforcesTheRolesAsWellAsTheApplication) {
  SqliteSessionStore local(fresh_database("roles"));
  record_session(local, "Trainee A", 100, 8);
  {
    PostgresSessionStore central(workstation(), kWorkstationPassword);
    synchronise(local, central);
  }
  const ServerSettings ws = workstation();
  const auto refused = [](const std::string& error) {
    return error.find("permission denied") != std::string::npos ||
           error.find("row-level security") != std::string::npos ||
           error.find("may not add") != std::string::npos ||
           error.find("must have admin option") != std::string::npos;
  };
  struct Forbidden {
    const char* what;
    ServerSettings login;
    std::string password;
    std::string sql;
  };
  const ServerSettings other_ws = server_->as("ws-02");
  const ServerSettings grey = server_->as("Dr. Grey");
  const std::vector<Forbidden> forbidden = {
      {"a workstation grades", ws, kWorkstationPassword,
       "INSERT INTO grades (session_id, instructor_id, graded_unix_ms, grade, comment) "
       "SELECT 1, id, 0, 'A', 'self-graded' FROM people WHERE role = 'instructor' LIMIT 1"},
      {"a workstation changes a grade", ws, kWorkstationPassword, "UPDATE grades SET grade = 'A'"},
      {"a workstation deletes a session", ws, kWorkstationPassword, "DELETE FROM sessions"},
      {"another workstation adds frames to it", other_ws, kOtherWorkstationPassword,
       "INSERT INTO frame_chunks VALUES (1, 100000, 1, 0, 0, 1, '\\x00')"},
      {"another workstation adds a metric to it", other_ws, kOtherWorkstationPassword,
       "INSERT INTO metrics VALUES (1, 'bonus', 100)"},
      {"a workstation publishes a scenario", ws, kWorkstationPassword,
       "INSERT INTO published_scenarios (name, title, content, sha256, published_unix_ms) "
       "VALUES ('x', 'x', '{}', 'x', 0)"},
      {"a workstation adds an instructor", ws, kWorkstationPassword,
       "INSERT INTO people (name, role) VALUES ('Dr. Fake', 'instructor')"},
      {"a workstation makes itself an instructor", ws, kWorkstationPassword,
       "GRANT liversim_instructor TO \"ws-01\""},
      {"a workstation calls the instructors' function", ws, kWorkstationPassword,
       "SELECT liversim_add_instructor('Dr. Fake', 'SCRAM-SHA-256$x')"},
      {"an instructor grades in another's name", grey, kInstructorPassword,
       "INSERT INTO grades (session_id, instructor_id, graded_unix_ms, grade, comment) "
       "SELECT 1, id, 0, 'F', 'forged' FROM people WHERE name = 'Dr. O''Neil'"},
      {"an instructor changes a session", grey, kInstructorPassword,
       "UPDATE sessions SET status = 'incomplete'"},
      {"an instructor uploads a session", grey, kInstructorPassword,
       "INSERT INTO sessions (uuid, trainee_id, scenario_id, device, started_unix_ms, status) "
       "VALUES (gen_random_uuid(), 1, 1, 'x', 0, 'complete')"},
  };
  for (const Forbidden& f : forbidden) {
    SCOPED_TRACE(f.what);
    const std::string error = run_sql_as(f.login, f.password, f.sql);
    EXPECT_TRUE(refused(error)) << "the server allowed it or said: " << error;
  }
  // A workstation's UPDATE of a finished session, even its own, matches no row under the policy.
  EXPECT_EQ(run_sql_as(ws, kWorkstationPassword, "UPDATE sessions SET frame_count = 0"), "");
  EXPECT_EQ(count_rows(*server_, "sessions WHERE frame_count = 100"), 1);
  EXPECT_EQ(count_rows(*server_, "grades"), 0);

  // The application refuses before the server is asked.
  PostgresSessionStore central(ws, kWorkstationPassword);
  EXPECT_FALSE(central.log_in_instructor("Dr. Grey", "wrong password"));
  EXPECT_FALSE(central.log_in_instructor("ws-02", kOtherWorkstationPassword))
      << "a workstation's login is no instructor's";
  EXPECT_THROW(central.add_instructor_account("Dr. New", "long enough password", nullptr),
               AccessDenied);
  PostgresSessionStore other(other_ws, kOtherWorkstationPassword);
  const std::optional<Instructor> from_other =
      other.log_in_instructor("Dr. Grey", kInstructorPassword);
  ASSERT_TRUE(from_other);
  EXPECT_THROW(central.store_grade(*from_other, 1, {"Dr. Grey", 0, std::nullopt, "A", ""}),
               AccessDenied)
      << "an Instructor of another store's log-in";
  EXPECT_THROW(central.publish_scenario(*from_other, "x", "{}"), AccessDenied);
  // A wrong password is refused by the server: a clear message, the login named, no password.
  try {
    PostgresSessionStore wrong(ws, "not the password");
    ADD_FAILURE() << "connected with a wrong password";
  } catch (const StorageError& e) {
    EXPECT_EQ(e.problem(), StorageProblem::refused) << e.what();
    EXPECT_NE(std::string(e.what()).find("ws-01"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("not the password"), std::string::npos) << e.what();
  }
  // An instructor who logged in adds an instructor; the new one can log in and grade.
  const std::optional<Instructor> grey_in =
      other.log_in_instructor("Dr. Grey", kInstructorPassword);
  ASSERT_TRUE(grey_in);
  const Instructor added = other.add_instructor_account("Dr. Robert'); DROP ROLE liversim_admin;--",
                                                        "a long new password", &*grey_in);
  EXPECT_TRUE(other.log_in_instructor(added.name(), "a long new password"));
  EXPECT_FALSE(other.log_in_instructor(added.name(), "a long new passwort"));
}

// Instructors publish scenarios centrally; workstations pull them into a folder, a changed one
// again, an unchanged one not. A text that is no valid scenario, or a name that is no plain file
// name, is refused.
TEST_F(TrainingCentre, PublishedScenariosArePulledByTheWorkstations) {
  PostgresSessionStore office(server_->as("Dr. Grey"), kInstructorPassword);
  const std::optional<Instructor> grey = office.log_in_instructor("Dr. Grey", kInstructorPassword);
  ASSERT_TRUE(grey);
  const auto read = [&](const fs::path& file) {
    std::ifstream in(file);
    std::ostringstream t;
    t << in.rdbuf();
    return t.str();
  };
  const std::string text = read(fs::path(LIVERSIM_TEST_DATA_DIR).parent_path().parent_path() /
                                "scenarios" / "palpation-hidden-lesion.json");
  ASSERT_FALSE(text.empty());
  office.publish_scenario(*grey, "hidden-lesion", text);
  EXPECT_THROW(office.publish_scenario(*grey, "../../etc/passwd", text), StorageError)
      << "a name that is no file name in the folder";
  try {
    office.publish_scenario(*grey, "broken", "{\"title\": \"no liver, no task\"}");
    ADD_FAILURE() << "published a scenario that does not validate";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("broken"), std::string::npos) << e.what();
  }

  PostgresSessionStore central(workstation(), kWorkstationPassword);
  ASSERT_EQ(central.published_scenarios().size(), 1u);
  EXPECT_EQ(central.published_scenarios()[0].title, "Palpation: find the hidden lesion");
  const fs::path folder = fs::path(LIVERSIM_TEST_OUTPUT_DIR) / "training-centre" / "pulled";
  fs::remove_all(folder);
  EXPECT_EQ(pull_scenarios(central, folder), std::vector<std::string>{"hidden-lesion"});
  EXPECT_EQ(read(folder / "hidden-lesion.json"), text);
  EXPECT_TRUE(pull_scenarios(central, folder).empty());
  std::string changed = text;
  const std::string title = "Palpation: find the hidden lesion";
  changed.replace(changed.find(title), title.size(), "Palpation, second edition");
  office.publish_scenario(*grey, "hidden-lesion", changed);
  EXPECT_EQ(central.published_scenarios().at(0).version, 2);
  EXPECT_EQ(central.published_scenarios().at(0).title, "Palpation, second edition");
  EXPECT_EQ(central.published_scenarios().at(0).published_by, "Dr. Grey");
  EXPECT_EQ(pull_scenarios(central, folder), std::vector<std::string>{"hidden-lesion"});
  EXPECT_EQ(read(folder / "hidden-lesion.json"), changed);
}

// A run that starts after now, and its outcome (a run under way now may predate the caller's
// last change).
TrainingCentreStatus run_and_wait(TrainingCentreSync& sync) {
  const TrainingCentreStatus now = sync.status();
  sync.run_soon();
  return sync.wait_for_runs(now.runs + (now.running ? 2 : 1), 120.0);
}

// The workstation's link runs in its own thread on its own connection to the file: the recorder
// commits chunk after chunk while it uploads, a server gone makes a run fail with the server
// named and the sessions waiting, and the next run once it is back uploads them.
TEST_F(TrainingCentre, TheWorkstationsLinkUploadsInTheBackgroundAndTheRecorderNeverWaitsOnIt) {
  PostgresSessionStore office(server_->as("Dr. Grey"), kInstructorPassword);
  const std::optional<Instructor> grey = office.log_in_instructor("Dr. Grey", kInstructorPassword);
  ASSERT_TRUE(grey);
  std::ifstream scenario_file(fs::path(LIVERSIM_TEST_DATA_DIR) / "scenario-small-resection.json");
  std::ostringstream scenario_text;
  scenario_text << scenario_file.rdbuf();
  office.publish_scenario(*grey, "small-resection", scenario_text.str());

  const fs::path database = fresh_database("background-link");
  SqliteSessionStore recorder(database);  // the workstation's own connection
  record_session(recorder, "Trainee A", 5000, 21);
  TrainingCentreLink link;
  link.server = workstation();
  link.password = kWorkstationPassword;
  link.sessions_database = database;
  link.scenario_folder = fs::path(LIVERSIM_TEST_OUTPUT_DIR) / "training-centre" / "link-pulled";
  fs::remove_all(link.scenario_folder);
  link.period_s = 3600.0;  // runs only when asked (and once at the start)
  TrainingCentreSync sync(link);

  // A session recorded while the link uploads: every commit goes through.
  const std::vector<ServoFrame> frames = testing::synthetic_frames(20'000, 22);
  const std::int64_t second = recorder.begin_session(
      {"Trainee B", "Wedge resection", "{}", "Scripted", 1'795'000'000'000, std::nullopt, {}});
  for (std::size_t first = 0; first < frames.size(); first += 50) {
    recorder.append_frames(second, std::span(frames).subspan(first, 50));
    ASSERT_NO_THROW(recorder.commit()) << "frame " << first;
    if (first % 2000 == 0) sync.run_soon();
  }
  // Just ended, its metrics not computed yet: it waits for them (an upload is never amended).
  const std::int64_t now_unix_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                                       std::chrono::system_clock::now().time_since_epoch())
                                       .count();
  recorder.end_session(second, now_unix_ms, SessionServoFigures{});
  TrainingCentreStatus status = run_and_wait(sync);
  EXPECT_TRUE(status.last_run_ok()) << status.problem.value_or("");
  EXPECT_EQ(status.uploaded, 1);
  const std::vector<MetricValue> metrics{{"path_length_m", 0.5}};
  recorder.store_metrics(second, metrics);
  status = run_and_wait(sync);
  EXPECT_TRUE(status.last_run_ok()) << status.problem.value_or("");
  EXPECT_EQ(status.uploaded, 2);
  EXPECT_EQ(status.waiting, 0);
  EXPECT_EQ(status.scenarios_pulled, 1);
  EXPECT_TRUE(fs::exists(link.scenario_folder / "small-resection.json"));
  EXPECT_GT(status.last_ok_unix_ms, 0);
  EXPECT_EQ(count_rows(*server_, "sessions"), 2);

  // The server gone: a run fails naming it; the recorder goes on; the session waits.
  server_->stop();
  record_session(recorder, "Trainee C", 500, 23);
  status = run_and_wait(sync);
  EXPECT_FALSE(status.last_run_ok());
  ASSERT_TRUE(status.problem);
  EXPECT_NE(status.problem->find("server " + server_name(workstation()) + ": cannot connect"),
            std::string::npos)
      << *status.problem;
  EXPECT_EQ(status.waiting, 1);
  record_session(recorder, "Trainee D", 500, 24);  // recording needs no server

  server_->start();
  status = run_and_wait(sync);
  EXPECT_TRUE(status.last_run_ok()) << status.problem.value_or("");
  EXPECT_EQ(status.uploaded, 4);
  EXPECT_EQ(status.waiting, 0);
  EXPECT_EQ(count_rows(*server_, "sessions"), 4);
}

// A server at schema version 1 with sessions in it: a workstation is told the administrator must
// migrate it; the migration keeps every session and adds version 2's table; a schema newer than
// this build is refused.
TEST(TrainingCentreSchema, AServerIsMigratedWithNothingLostAndANewerOneIsRefused) {
  ThrowawayPostgres server;
  const ServerSettings admin = server.administrator();
  const char* password = ThrowawayPostgres::kAdministratorPassword;
  PostgresSessionStore::set_up_server(admin, password, 1);
  PostgresSessionStore::add_server_login(admin, password, "ws-01", kWorkstationPassword,
                                         ServerLoginKind::workstation);
  // A session sent at version 1 (plain SQL: this build's store opens only its own version).
  const std::string at_v1 = run_sql_as(
      server.as("ws-01"), kWorkstationPassword,
      "BEGIN; INSERT INTO people (name, role) VALUES ('Trainee V1', 'trainee');"
      "INSERT INTO scenarios (sha256, title, content) VALUES ('h', 'Old', '{}');"
      "INSERT INTO sessions (uuid, trainee_id, scenario_id, device, started_unix_ms, status, "
      "frame_count) VALUES ('6f1c2f43-5a2b-4d3e-8f00-0123456789ab', 1, 1, 'Omni', 1, "
      "'complete', 0); INSERT INTO metrics VALUES (1, 'peak_force_n', 2.5);"
      "INSERT INTO events (session_id, time_s, kind, detail) VALUES (1, 0.5, 'grasp', '');"
      "COMMIT;");
  ASSERT_EQ(at_v1, "");
  try {
    PostgresSessionStore central(server.as("ws-01"), kWorkstationPassword);
    ADD_FAILURE() << "opened a version-1 server";
  } catch (const StorageError& e) {
    EXPECT_NE(std::string(e.what()).find("version 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("server set-up"), std::string::npos) << e.what();
  }
  PostgresSessionStore::set_up_server(admin, password);
  PostgresSessionStore::set_up_server(admin, password);  // again: nothing to do
  PostgresSessionStore central(server.as("ws-01"), kWorkstationPassword);
  EXPECT_EQ(central.schema_version(), PostgresSessionStore::kSchemaVersion);
  ASSERT_EQ(central.sessions().size(), 1u);
  EXPECT_EQ(central.sessions()[0].uuid, "6f1c2f43-5a2b-4d3e-8f00-0123456789ab");
  EXPECT_EQ(central.metrics(central.sessions()[0].id),
            (std::vector<MetricValue>{{"peak_force_n", 2.5}}));
  // Version 4: a session before it had one hand, the right one, and so had its events.
  EXPECT_FALSE(central.sessions()[0].left_hand);
  EXPECT_EQ(central.events(central.sessions()[0].id),
            (std::vector<SessionEvent>{{0.5, SessionEventKind::grasp, "", Hand::right}}));
  EXPECT_TRUE(central.published_scenarios().empty());

  ASSERT_EQ(run_sql_as(admin, password, "UPDATE liversim_schema SET version = 99"), "");
  try {
    PostgresSessionStore newer(server.as("ws-01"), kWorkstationPassword);
    ADD_FAILURE() << "opened a newer server";
  } catch (const StorageError& e) {
    EXPECT_EQ(e.problem(), StorageProblem::newer_version) << e.what();
  }
}

// The TLS options reach libpq as they are: with the centre's certificate authority the
// connection is encrypted and the server verified; trusting another authority, it is refused.
TEST(TrainingCentreTls, TheConnectionIsEncryptedAndAServerSignedByAnotherAuthorityIsRefused) {
  ThrowawayPostgres server({.tls = true});
  const ServerSettings admin = server.administrator();
  ASSERT_EQ(admin.ssl_mode, "verify-full");
  PostgresSessionStore::set_up_server(admin, ThrowawayPostgres::kAdministratorPassword);
  PostgresSessionStore::add_server_login(admin, ThrowawayPostgres::kAdministratorPassword, "ws-01",
                                         kWorkstationPassword, ServerLoginKind::workstation);
  PostgresSessionStore central(server.as("ws-01"), kWorkstationPassword);
  EXPECT_TRUE(central.connection_is_encrypted());
  ServerSettings wrong_authority = server.as("ws-01");
  wrong_authority.ssl_root_cert = server.other_certificate_authority();
  try {
    PostgresSessionStore refused(wrong_authority, kWorkstationPassword);
    ADD_FAILURE() << "trusted a server signed by another authority";
  } catch (const StorageError& e) {
    EXPECT_EQ(e.problem(), StorageProblem::unreachable) << e.what();
    EXPECT_NE(std::string(e.what()).find("certificate"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace liversim
