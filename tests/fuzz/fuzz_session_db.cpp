// Fuzz target: the sessions database loader (sqlite_session_store.h) on a fuzzed SQLite file.
// The file is opened as the review and replay windows open it (read-only) and then as the
// workstation does (for writing: migrated, sessions left recording closed), and everything of
// every session is loaded: its parts, its upload to the training centre (read as the link reads
// it, chunks included), and an instructor's log-in (the stored password hash checked). The store
// promises its data or a StorageError naming the file.

#include "fuzz_support.h"
#include "liversim/storage/sqlite_session_store.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <system_error>

namespace {

using namespace liversim;

// One loader: a StorageError here (a damaged chunk, say) must not keep the others from running.
template <typename Load>
void load(const std::string& file, Load&& what) {
  try {
    what();
  } catch (const StorageError& error) {
    LIVERSIM_FUZZ_CHECK(std::string(error.what()).starts_with("sessions database " + file + ": "));
  }
}

// The seeds' instructor account and trainee (make_seeds.cpp), and a server name.
constexpr const char* kInstructor = "instructor-b";
constexpr const char* kPassword = "seed password";
constexpr const char* kTrainee = "trainee-a";
constexpr const char* kServer = "fuzz-server";

// A transfer's chunks read through as the upload streams them; none starts or counts below 0.
void read_chunks(const ChunkSource& source) {
  if (!source) return;
  source(
      [](const StoredChunk& chunk) { LIVERSIM_FUZZ_CHECK(chunk.first >= 0 && chunk.count >= 0); });
}

void load_everything(const std::filesystem::path& file, SqliteSessionStore::Access access) {
  const std::string name = file.string();
  load(name, [&] {
    SqliteSessionStore store(file, access);
    load(name, [&] { store.schema_version(); });
    load(name, [&] { store.integrity_check(); });
    // A log-in runs the hash the file holds, at the cost the file says; only when there are
    // accounts (an unknown name costs a hash at the interactive level, which would slow the run).
    load(name, [&] {
      if (!store.has_instructor_accounts()) return;
      store.log_in_instructor(kInstructor, kPassword);
    });
    load(name, [&] { store.sessions_of_trainee(kTrainee); });
    load(name, [&] { store.sessions_to_upload(kServer); });
    load(name, [&] { store.uploaded_session_uuids(kServer); });
    std::vector<SessionSummary> sessions;
    load(name, [&] { sessions = store.sessions(); });
    int loaded = 0;
    for (const SessionSummary& session : sessions) {
      if (++loaded > 16) break;  // the same code again for each further one
      const std::int64_t id = session.id;
      load(name, [&] { store.frames(id); });
      load(name, [&] { store.events(id); });
      load(name, [&] { store.inputs(id); });
      load(name, [&] { store.replay_setup(id); });
      load(name, [&] { store.metrics(id); });
      load(name, [&] { store.grades(id); });
      load(name, [&] { store.scenario_text(id); });
      load(name, [&] { store.upload_state(id, kServer); });
      load(name, [&] {
        const SessionTransfer transfer = store.transfer_of(id);
        read_chunks(transfer.frame_chunks);
        read_chunks(transfer.input_chunks);
      });
    }
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto& folder = fuzz::scratch_folder();
  // SQLite's companions of the last input would change how this one reads.
  std::error_code ignored;
  for (const char* companion : {"-wal", "-shm", "-journal"})
    std::filesystem::remove(folder / (std::string("sessions.sqlite") + companion), ignored);
  const auto file = fuzz::write_scratch_file("sessions.sqlite", data, size);
  load_everything(file, SqliteSessionStore::Access::read_only);
  load_everything(file, SqliteSessionStore::Access::read_write);
  return 0;
}
