#include "liversim/storage/session_upload.h"

#include "stored_rows.h"

#include <fstream>
#include <sstream>
#include <system_error>

namespace liversim {

SyncReport synchronise(SqliteSessionStore& local, PostgresSessionStore& central) {
  SyncReport report;
  const std::string server = server_name(central.settings());
  const std::vector<std::int64_t> pending = local.sessions_to_upload(server);
  for (std::size_t k = 0; k < pending.size(); ++k) {
    const std::int64_t session = pending[k];
    SessionTransfer transfer = local.transfer_of(session);
    std::int64_t bytes = 0;
    for (ChunkSource* source : {&transfer.frame_chunks, &transfer.input_chunks}) {
      *source = [inner = std::move(*source), &bytes](const ChunkSink& sink) {
        inner([&](const StoredChunk& chunk) {
          bytes += static_cast<std::int64_t>(chunk.data.size());
          sink(chunk);
        });
      };
    }
    try {
      if (central.receive_session(transfer)) {
        ++report.uploaded;
        report.chunk_bytes_sent += bytes;
      } else {
        ++report.already_there;
      }
    } catch (const std::exception& e) {  // StorageError, AccessDenied: the server's side
      report.problem = "session " + std::to_string(session) + " (" + transfer.summary.uuid +
                       ") was not uploaded: " + e.what();
      report.waiting = static_cast<int>(pending.size() - k);
      local.note_upload_problem(session, server, e.what());
      return report;
    }
    local.mark_uploaded(session, server, stored_rows::unix_ms_now());
  }
  try {
    const std::vector<std::string> uuids = local.uploaded_session_uuids(server);
    report.grades_pulled = local.store_shared_grades(central.grades_of_sessions(uuids));
  } catch (const StorageError& e) {
    report.problem = std::string("the grades were not pulled: ") + e.what();
  }
  return report;
}

std::vector<std::string> pull_scenarios(PostgresSessionStore& central,
                                        const std::filesystem::path& folder) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::create_directories(folder, error);
  if (error)
    throw StorageError(
        "scenario folder " + folder.string() + ": cannot create it (" + error.message() + ")",
        StorageProblem::unreachable);
  std::vector<std::string> written;
  for (const PublishedScenario& scenario : central.published_scenarios()) {
    const fs::path file = folder / (scenario.name + ".json");
    {
      std::ifstream existing(file, std::ios::binary);
      std::ostringstream text;
      text << existing.rdbuf();
      if (existing && text.str() == scenario.text) continue;
    }
    const fs::path temporary = folder / ("." + scenario.name + ".json.part");
    {
      std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
      out << scenario.text;
      out.flush();
      if (!out)
        throw StorageError("scenario folder " + folder.string() + ": cannot write " +
                               temporary.filename().string(),
                           StorageProblem::unreachable);
    }
    fs::rename(temporary, file, error);
    if (error)
      throw StorageError("scenario folder " + folder.string() + ": cannot put " +
                             file.filename().string() + " in place (" + error.message() + ")",
                         StorageProblem::unreachable);
    written.push_back(scenario.name);
  }
  return written;
}

}  // namespace liversim
