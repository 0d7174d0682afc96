#include "sessions_command.h"

#include "liversim/scenario/scenario.h"
#include "liversim/sessions/session_export.h"
#include "liversim/storage/sqlite_session_store.h"
#include "server_command.h"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>

namespace liversim::cli {

namespace {

struct SessionsOptions {
  std::filesystem::path database;
  ServerConnectionOptions server;  // instead of a database: the training centre's server
  std::int64_t session = 0;
  std::filesystem::path frames_csv, left_frames_csv, events_csv, metrics_csv;
};

void print_list(SessionStore& store) {
  const std::vector<SessionSummary> sessions = store.sessions();
  std::cout << "id,trainee,scenario,scenario_sha256,device,started_unix_ms,ended_unix_ms,status,"
               "frames,servo_rate_hz,servo_period_p99_ms,missed_deadlines,dropped_frames,"
               "left_device,left_frames\n";
  for (const SessionSummary& s : sessions) {
    std::cout << s.id << ',' << csv_field(s.trainee) << ',' << csv_field(s.scenario_title) << ','
              << s.scenario_sha256 << ',' << csv_field(s.device) << ',' << s.started_unix_ms << ',';
    if (s.ended_unix_ms) std::cout << *s.ended_unix_ms;
    std::cout << ',' << session_status_name(s.status) << ',' << s.frame_count << ',';
    if (s.servo)
      std::cout << s.servo->rate_hz << ',' << s.servo->period_p99_ms << ','
                << s.servo->missed_deadlines << ',' << s.servo->dropped_frames;
    else
      std::cout << ",,,";
    // The left hand's device (empty for a one-handed session).
    std::cout << ',';
    if (s.left_hand)
      std::cout << csv_field(s.left_hand->device) << ',' << s.left_frame_count;
    else
      std::cout << ',';
    std::cout << '\n';
  }
}

int export_session(SessionStore& store, const SessionsOptions& o) {
  const std::string where = o.server.url.empty() ? o.database.string() : o.server.url;
  const SessionSummary* found = nullptr;
  const std::vector<SessionSummary> sessions = store.sessions();
  for (const SessionSummary& s : sessions)
    if (s.id == o.session) found = &s;
  if (!found) {
    std::cerr << "error: " << where << " has no session " << o.session << '\n';
    return 1;
  }
  if (!o.left_frames_csv.empty() && !found->left_hand) {
    std::cerr << "error: session " << o.session << " of " << where
              << " had no device in the left hand: it has no left-hand frames to export\n";
    return 1;
  }
  auto write = [&](const std::filesystem::path& file, auto&& what) {
    std::ofstream out(file);
    if (out) what(out);
    out.flush();
    if (!out) {
      std::cerr << "error: cannot write " << file.string() << '\n';
      return false;
    }
    return true;
  };
  if (!write(o.frames_csv,
             [&](std::ostream& out) { write_frames_csv(store.frames(o.session), out); }))
    return 1;
  if (!o.left_frames_csv.empty() && !write(o.left_frames_csv, [&](std::ostream& out) {
        write_frames_csv(store.frames(o.session, Hand::left), out);
      }))
    return 1;
  if (!o.events_csv.empty() && !write(o.events_csv, [&](std::ostream& out) {
        write_events_csv(store.events(o.session), out);
      }))
    return 1;
  if (!o.metrics_csv.empty() && !write(o.metrics_csv, [&](std::ostream& out) {
        const ScenarioReading reading = read_scenario(store.scenario_text(o.session));
        const std::vector<MetricValue> metrics = store.metrics(o.session);
        write_metrics_csv(metrics,
                          grade_against_rubric(reading.scenario ? reading.scenario->rubric
                                                                : std::vector<RubricCriterion>{},
                                               metrics),
                          out);
      }))
    return 1;
  std::cout << "wrote session " << o.session << " to " << o.frames_csv.string()
            << (o.left_frames_csv.empty() ? "" : ", " + o.left_frames_csv.string())
            << (o.events_csv.empty() ? "" : ", " + o.events_csv.string())
            << (o.metrics_csv.empty() ? "" : ", " + o.metrics_csv.string()) << '\n';
  return 0;
}

}  // namespace

std::function<std::optional<int>()> add_sessions_command(CLI::App& app) {
  auto options = std::make_shared<SessionsOptions>();
  auto* sessions =
      app.add_subcommand("sessions", "List the sessions of a sessions database, or export one");
  sessions->require_subcommand(1);
  // The sessions of a workstation's database file, or of the training centre's server.
  const auto store_options = [&](CLI::App* sub) {
    sub->add_option("--database", options->database, "Sessions database (.sqlite)")
        ->check(CLI::ExistingFile);
    add_server_connection_options(*sub, options->server, false);
    sub->callback([options, sub] {
      if (options->database.empty() == options->server.url.empty())
        throw CLI::ValidationError(sub->get_name(), "give one of --database and --server");
    });
  };
  auto* list = sessions->add_subcommand("list", "Print every session as a CSV line");
  store_options(list);
  auto* exported = sessions->add_subcommand(
      "export",
      "Write a session's frames (and events, metrics) as CSV, every number at full precision");
  store_options(exported);
  exported->add_option("--session", options->session, "Session id (from `sessions list`)")
      ->required();
  exported->add_option("--frames", options->frames_csv, "Output CSV of the frames")->required();
  exported->add_option("--left-frames", options->left_frames_csv,
                       "Output CSV of the left hand's device's frames (a two-handed session)");
  exported->add_option("--events", options->events_csv,
                       "Output CSV of the events, with their hand");
  exported->add_option("--metrics", options->metrics_csv,
                       "Output CSV of the metrics against the scenario's rubric, and the score");
  return [=]() -> std::optional<int> {
    if (!sessions->parsed()) return std::nullopt;
    try {
      std::unique_ptr<SessionStore> store;
      if (options->server.url.empty())
        store = std::make_unique<SqliteSessionStore>(options->database,
                                                     SqliteSessionStore::Access::read_only);
      else
        store = connect_to_server(options->server);
      if (list->parsed()) {
        print_list(*store);
        return 0;
      }
      return export_session(*store, *options);
    } catch (const std::exception& e) {  // StorageError, or a malformed server URL
      std::cerr << "error: " << e.what() << '\n';
      return 1;
    }
  };
}

}  // namespace liversim::cli
