// The training centre's load bench (docs/training-centre.md): N workstations upload their
// sessions to one PostgreSQL server at the same moment. Each workstation's database is a copy of
// a recorded one (a 10-minute session of `liversim-cli record`,
// tests/storage/training_centre_load.sh) with new session UUIDs; the server is a throwaway cluster
// on loopback that writes durably (fsync on, as a real server). Prints the time each upload took,
// the total and the throughput, checks that the server holds every session whole, and writes the
// report as Markdown.
//   liversim_training_centre_load --template FILE [--workstations 20] [--work DIR] [--output FILE]
#include "liversim/storage/postgres_session_store.h"
#include "liversim/storage/session_upload.h"
#include "liversim/storage/sqlite_session_store.h"
#include "throwaway_postgres.h"

#include <sqlite3.h>

#include <algorithm>
#include <barrier>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;
using namespace liversim;
using Clock = std::chrono::steady_clock;

namespace {

void sql(sqlite3* db, const std::string& statement, const fs::path& file) {
  char* message = nullptr;
  if (sqlite3_exec(db, statement.c_str(), nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string what = message ? message : "unknown error";
    sqlite3_free(message);
    throw std::runtime_error(file.string() + ": " + statement + ": " + what);
  }
}

// A workstation's database: the template copied whole (VACUUM INTO: one consistent file), its
// sessions given new UUIDs so that the server takes each copy as another session, none uploaded.
void copy_workstation_database(const fs::path& from, const fs::path& to) {
  fs::remove(to);
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(from.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK)
    throw std::runtime_error("cannot open " + from.string());
  std::string quoted = to.string();
  for (std::size_t at = 0; (at = quoted.find('\'', at)) != std::string::npos; at += 2)
    quoted.insert(at, 1, '\'');
  sql(db, "VACUUM INTO '" + quoted + "'", from);
  sqlite3_close(db);
  if (sqlite3_open(to.c_str(), &db) != SQLITE_OK)
    throw std::runtime_error("cannot open " + to.string());
  {
    SqliteSessionStore migrate(to);  // to this build's schema first
  }
  sqlite3_stmt* select = nullptr;
  sqlite3_prepare_v2(db, "SELECT id FROM sessions", -1, &select, nullptr);
  std::vector<std::int64_t> ids;
  while (sqlite3_step(select) == SQLITE_ROW) ids.push_back(sqlite3_column_int64(select, 0));
  sqlite3_finalize(select);
  for (const std::int64_t id : ids)
    sql(db, "UPDATE sessions SET uuid = '" + new_uuid() + "' WHERE id = " + std::to_string(id), to);
  sql(db, "DELETE FROM session_uploads", to);
  sqlite3_close(db);
}

struct Upload {
  double seconds = 0.0;
  SyncReport report;
  std::string error;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  fs::path template_file, work = fs::temp_directory_path() / "liversim-load", output;
  int workstations = 20;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--template" && has_value)
      template_file = argv[++i];
    else if (a == "--workstations" && has_value)
      workstations = std::stoi(argv[++i]);
    else if (a == "--work" && has_value)
      work = argv[++i];
    else if (a == "--output" && has_value)
      output = argv[++i];
    else {
      std::cerr << "usage: " << argv[0]
                << " --template FILE [--workstations N] [--work DIR] [--output FILE.md]\n";
      return 2;
    }
  }
  if (template_file.empty() || workstations < 1) {
    std::cerr << "error: give --template, a sessions database to copy, and N >= 1\n";
    return 2;
  }
  try {
    // What one workstation uploads.
    std::int64_t template_sessions = 0, template_frames = 0;
    double template_minutes = 0.0;
    {
      SqliteSessionStore store(template_file, SqliteSessionStore::Access::read_only);
      for (const SessionSummary& s : store.sessions()) {
        if (s.status == SessionStatus::recording) continue;
        ++template_sessions;
        template_frames += s.frame_count;
        if (s.ended_unix_ms) template_minutes += (*s.ended_unix_ms - s.started_unix_ms) / 60e3;
      }
    }
    if (template_sessions == 0)
      throw std::runtime_error(template_file.string() + " has no finished session");
    fs::create_directories(work);
    std::vector<fs::path> databases;
    for (int k = 0; k < workstations; ++k) {
      databases.push_back(work / ("ws" + std::to_string(k + 1) + ".sqlite"));
      copy_workstation_database(template_file, databases.back());
    }
    const auto database_bytes = fs::file_size(databases.front());

    testing::ThrowawayPostgres::Options server_options;
    server_options.durable = true;
    testing::ThrowawayPostgres server(server_options);
    const ServerSettings admin = server.administrator();
    PostgresSessionStore::set_up_server(admin, testing::ThrowawayPostgres::kAdministratorPassword);
    for (int k = 0; k < workstations; ++k)
      PostgresSessionStore::add_server_login(
          admin, testing::ThrowawayPostgres::kAdministratorPassword, "ws" + std::to_string(k + 1),
          "load password " + std::to_string(k), ServerLoginKind::workstation);
    std::cout << workstations << " workstations, each " << template_sessions << " session(s), "
              << template_frames << " frames, " << std::fixed << std::setprecision(1)
              << template_minutes << " min, database " << database_bytes / 1e6 << " MB\n\n";

    // All at once: each thread connects and uploads when the last is ready.
    std::vector<Upload> uploads(static_cast<std::size_t>(workstations));
    std::barrier start(workstations + 1);
    std::vector<std::thread> threads;
    for (int k = 0; k < workstations; ++k)
      threads.emplace_back([&, k] {
        Upload& u = uploads[static_cast<std::size_t>(k)];
        start.arrive_and_wait();
        const auto t0 = Clock::now();
        try {
          PostgresSessionStore central(server.as("ws" + std::to_string(k + 1)),
                                       "load password " + std::to_string(k));
          SqliteSessionStore local(databases[static_cast<std::size_t>(k)]);
          u.report = synchronise(local, central);
        } catch (const std::exception& e) {
          u.error = e.what();
        }
        u.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
      });
    const auto t0 = Clock::now();
    start.arrive_and_wait();
    for (std::thread& t : threads) t.join();
    const double wall_s = std::chrono::duration<double>(Clock::now() - t0).count();

    // The server holds every session whole.
    PostgresSessionStore check(admin, testing::ThrowawayPostgres::kAdministratorPassword);
    std::int64_t stored_sessions = 0, stored_frames = 0;
    for (const SessionSummary& s : check.sessions()) {
      ++stored_sessions;
      stored_frames += s.frame_count;
    }
    std::int64_t bytes = 0;
    int failed = 0;
    std::vector<double> seconds;
    for (const Upload& u : uploads) {
      bytes += u.report.chunk_bytes_sent;
      seconds.push_back(u.seconds);
      if (!u.error.empty() || u.report.problem || u.report.uploaded != template_sessions) {
        ++failed;
        std::cerr << "a workstation's upload failed: "
                  << (u.error.empty() ? u.report.problem.value_or("not all uploaded") : u.error)
                  << '\n';
      }
    }
    const bool whole = stored_sessions == workstations * template_sessions &&
                       stored_frames == workstations * template_frames;

    std::ostringstream report;
    report << std::fixed << std::setprecision(1);
    report << "| workstations | sessions each | frames each | session length | chunk bytes each | "
              "all uploaded in | per workstation (min / median / max) | throughput |\n"
           << "|---|---|---|---|---|---|---|---|\n"
           << "| " << workstations << " | " << template_sessions << " | " << template_frames
           << " | " << template_minutes << " min | " << bytes / workstations / 1e6 << " MB | "
           << wall_s << " s | " << *std::min_element(seconds.begin(), seconds.end()) << " / "
           << median(seconds) << " / " << *std::max_element(seconds.begin(), seconds.end())
           << " s | " << bytes / wall_s / 1e6 << " MB/s, " << std::setprecision(0)
           << workstations * template_frames / wall_s << " frames/s, " << std::setprecision(1)
           << workstations * template_minutes / (wall_s / 60.0)
           << " session-minutes per minute |\n";
    report << "\nServer: stored " << stored_sessions << " sessions, " << stored_frames
           << " frames (" << (whole ? "every session whole" : "NOT every session whole") << "); "
           << failed << " uploads failed.\n";
    std::cout << report.str();
    if (!output.empty()) {
      std::ofstream out(output);
      out << report.str();
      if (!out) throw std::runtime_error("cannot write " + output.string());
    }
    for (const fs::path& d : databases)
      for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(d.string() + suffix);
    return failed == 0 && whole ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 1;
  }
}
