#include "liversim/storage/training_centre_sync.h"

#include "liversim/storage/postgres_session_store.h"
#include "liversim/storage/sqlite_session_store.h"
#include "stored_rows.h"

#include <chrono>
#include <memory>

namespace liversim {

TrainingCentreSync::TrainingCentreSync(TrainingCentreLink link)
    : link_(std::move(link)), thread_([this] { loop(); }) {}

TrainingCentreSync::~TrainingCentreSync() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void TrainingCentreSync::run_soon() {
  {
    std::lock_guard lock(mutex_);
    run_requested_ = true;
  }
  changed_.notify_all();
}

TrainingCentreStatus TrainingCentreSync::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

TrainingCentreStatus TrainingCentreSync::wait_for_runs(std::int64_t runs, double patience_s) const {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, std::chrono::duration<double>(patience_s),
                    [&] { return status_.runs >= runs; });
  return status_;
}

void TrainingCentreSync::loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait_for(lock, std::chrono::duration<double>(link_.period_s),
                      [&] { return stop_ || run_requested_; });
    if (stop_) return;
    run_requested_ = false;
    status_.running = true;
    lock.unlock();
    run_once();
    lock.lock();
    changed_.notify_all();
  }
}

void TrainingCentreSync::run_once() {
  // Everything reached through the network or the file is caught: the thread goes on, and the
  // status says what stopped this run.
  SyncReport report;
  int scenarios = 0;
  std::optional<std::string> problem;
  std::unique_ptr<SqliteSessionStore> local;
  try {
    local = std::make_unique<SqliteSessionStore>(link_.sessions_database);
    PostgresSessionStore central(link_.server, link_.password);
    report = synchronise(*local, central);
    problem = report.problem;
    if (!link_.scenario_folder.empty())
      scenarios = static_cast<int>(pull_scenarios(central, link_.scenario_folder).size());
  } catch (const std::exception& e) {
    problem = e.what();
    try {  // the server out of reach: every finished session waits
      if (local)
        report.waiting =
            static_cast<int>(local->sessions_to_upload(server_name(link_.server)).size());
    } catch (const std::exception&) {
    }
  }
  std::lock_guard lock(mutex_);
  ++status_.runs;
  status_.running = false;
  status_.problem = problem;
  status_.uploaded += report.uploaded;
  status_.waiting = report.waiting;
  status_.grades_pulled += report.grades_pulled;
  status_.scenarios_pulled += scenarios;
  if (!problem) status_.last_ok_unix_ms = stored_rows::unix_ms_now();
}

}  // namespace liversim
