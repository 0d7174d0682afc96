#pragma once
// The workstation's link to the training centre: a thread of its own that, every period and
// whenever asked (a session ended), uploads the finished sessions of the workstation's sessions
// database, pulls the grades and the published scenarios (synchronise, pull_scenarios). It opens
// its own connection to the SQLite file, so the recorder never waits on it, and reconnects to the
// server each run, so a network cut only makes a run fail: the sessions wait for the next one.

#include "liversim/storage/server_settings.h"
#include "liversim/storage/session_upload.h"

#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace liversim {

struct TrainingCentreLink {
  ServerSettings server;
  std::string password;  // held in memory only; empty: libpq's ~/.pgpass or a certificate
  std::filesystem::path sessions_database;
  std::filesystem::path scenario_folder;  // where published scenarios are pulled; empty: none
  double period_s = 60.0;                 // between runs (a run is also asked for when needed)
};

struct TrainingCentreStatus {
  std::int64_t runs = 0;               // finished, successful or not
  bool running = false;                // a run is under way
  std::optional<std::string> problem;  // what stopped the last run, naming the server
  int uploaded = 0;                    // sessions uploaded by this link since it started
  int waiting = 0;                     // finished sessions not on the server after the last run
  int grades_pulled = 0;               // since it started
  int scenarios_pulled = 0;            // new or changed scenario files written since it started
  std::int64_t last_ok_unix_ms = 0;    // when a run last succeeded; 0: never
  // The last run reached the server and did all it had to.
  bool last_run_ok() const { return runs > 0 && !problem; }
};

class TrainingCentreSync {
 public:
  // Starts the thread; its first run is at once.
  explicit TrainingCentreSync(TrainingCentreLink link);
  // Stops the thread after the run under way (an upload is one transaction per session: one cut
  // short leaves nothing on the server and is done whole next time).
  ~TrainingCentreSync();
  TrainingCentreSync(const TrainingCentreSync&) = delete;
  TrainingCentreSync& operator=(const TrainingCentreSync&) = delete;

  // Asks for a run now (after the one under way, if any).
  void run_soon();
  TrainingCentreStatus status() const;
  const ServerSettings& server() const { return link_.server; }
  const TrainingCentreLink& link() const { return link_; }
  // Waits until `runs` runs have finished, or `patience_s` has passed; the status then.
  TrainingCentreStatus wait_for_runs(std::int64_t runs, double patience_s) const;

 private:
  void loop();
  void run_once();

  const TrainingCentreLink link_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  bool stop_ = false;
  bool run_requested_ = true;
  TrainingCentreStatus status_;
  std::thread thread_;  // last: started once the rest is ready
};

}  // namespace liversim
