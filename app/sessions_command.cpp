#include "sessions_command.h"

#include "liversim/storage/sqlite_session_store.h"

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
  std::int64_t session = 0;
  std::filesystem::path frames_csv, events_csv;
};

void print_list(SqliteSessionStore& store) {
  const std::vector<SessionSummary> sessions = store.sessions();
  std::cout << "id,trainee,scenario,scenario_sha256,device,started_unix_ms,ended_unix_ms,status,"
               "frames,servo_rate_hz,servo_period_p99_ms,missed_deadlines,dropped_frames\n";
  for (const SessionSummary& s : sessions) {
    std::cout << s.id << ',' << std::quoted(s.trainee) << ',' << std::quoted(s.scenario_title)
              << ',' << s.scenario_sha256 << ',' << std::quoted(s.device) << ','
              << s.started_unix_ms << ',';
    if (s.ended_unix_ms) std::cout << *s.ended_unix_ms;
    std::cout << ',' << session_status_name(s.status) << ',' << s.frame_count << ',';
    if (s.servo)
      std::cout << s.servo->rate_hz << ',' << s.servo->period_p99_ms << ','
                << s.servo->missed_deadlines << ',' << s.servo->dropped_frames;
    else
      std::cout << ",,,";
    std::cout << '\n';
  }
}

// Full precision: the CSV reads back to the stored doubles.
void write_frames(const std::vector<ServoFrame>& frames, std::ostream& out) {
  out << std::setprecision(17)
      << "time_s,x_mm,y_mm,z_mm,vx_mm_per_s,vy_mm_per_s,vz_mm_per_s,fx_n,fy_n,fz_n,buttons\n";
  for (const ServoFrame& f : frames) {
    out << f.time_s;
    for (int k = 0; k < 3; ++k) out << ',' << f.sample.position_mm[k];
    for (int k = 0; k < 3; ++k) out << ',' << f.sample.velocity_mm_per_s[k];
    for (int k = 0; k < 3; ++k) out << ',' << f.force_n[k];
    out << ',' << f.sample.buttons << '\n';
  }
}

void write_events(const std::vector<SessionEvent>& events, std::ostream& out) {
  out << std::setprecision(17) << "time_s,kind,detail\n";
  for (const SessionEvent& e : events)
    out << e.time_s << ',' << session_event_name(e.kind) << ',' << std::quoted(e.detail) << '\n';
}

int export_session(SqliteSessionStore& store, const SessionsOptions& o) {
  bool found = false;
  for (const SessionSummary& s : store.sessions()) found |= s.id == o.session;
  if (!found) {
    std::cerr << "error: " << o.database.string() << " has no session " << o.session << '\n';
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
  if (!write(o.frames_csv, [&](std::ostream& out) { write_frames(store.frames(o.session), out); }))
    return 1;
  if (!o.events_csv.empty() &&
      !write(o.events_csv, [&](std::ostream& out) { write_events(store.events(o.session), out); }))
    return 1;
  std::cout << "wrote session " << o.session << " to " << o.frames_csv.string()
            << (o.events_csv.empty() ? "" : " and " + o.events_csv.string()) << '\n';
  return 0;
}

}  // namespace

std::function<std::optional<int>()> add_sessions_command(CLI::App& app) {
  auto options = std::make_shared<SessionsOptions>();
  auto* sessions =
      app.add_subcommand("sessions", "List the sessions of a sessions database, or export one");
  sessions->require_subcommand(1);
  auto* list = sessions->add_subcommand("list", "Print every session as a CSV line");
  list->add_option("--database", options->database, "Sessions database (.sqlite)")
      ->required()
      ->check(CLI::ExistingFile);
  auto* exported = sessions->add_subcommand(
      "export", "Write a session's frames (and events) as CSV, every number at full precision");
  exported->add_option("--database", options->database, "Sessions database (.sqlite)")
      ->required()
      ->check(CLI::ExistingFile);
  exported->add_option("--session", options->session, "Session id (from `sessions list`)")
      ->required();
  exported->add_option("--frames", options->frames_csv, "Output CSV of the frames")->required();
  exported->add_option("--events", options->events_csv, "Output CSV of the events");
  return [=]() -> std::optional<int> {
    if (!sessions->parsed()) return std::nullopt;
    try {
      SqliteSessionStore store(options->database, SqliteSessionStore::Access::read_only);
      if (list->parsed()) {
        print_list(store);
        return 0;
      }
      return export_session(store, *options);
    } catch (const StorageError& e) {
      std::cerr << "error: " << e.what() << '\n';
      return 1;
    }
  };
}

}  // namespace liversim::cli
