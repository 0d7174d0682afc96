#pragma once
// A workstation and the training centre's server (docs/training-centre.md): finished sessions go
// up from the workstation's SQLite file exactly once (keyed by their UUIDs, each in one
// transaction), grades come back down, and published scenarios are pulled into a folder. A
// network cut only delays this: recording never waits for the server.

#include "liversim/storage/postgres_session_store.h"
#include "liversim/storage/sqlite_session_store.h"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace liversim {

struct SyncReport {
  int uploaded = 0;       // stored on the server now
  int already_there = 0;  // the server had them already (an upload whose note was lost)
  int waiting = 0;        // not uploaded: the problem below stopped the run before them
  std::int64_t chunk_bytes_sent = 0;
  int grades_pulled = 0;
  // What stopped the run (the server gone mid-upload...); the sessions not uploaded wait for the
  // next run, and the session it stopped at has the problem noted (upload_state).
  std::optional<std::string> problem;
};

// Uploads each finished session of `local` that the server does not have, oldest first, then
// pulls the grades of the sessions the server has. Throws nothing a server or network fault
// causes: it is reported; StorageError from the local file is thrown.
SyncReport synchronise(SqliteSessionStore& local, PostgresSessionStore& central);

// Writes each published scenario to folder/NAME.json when it is new or changed there (a
// temporary file renamed into place: a reader never sees half a file). Returns the names
// written. Throws StorageError naming the folder when it cannot be written.
std::vector<std::string> pull_scenarios(PostgresSessionStore& central,
                                        const std::filesystem::path& folder);

}  // namespace liversim
