// Writes the generated part of the seed corpora (docs/fuzzing.md, "Seeds"): binary and
// hand-to-write inputs made from the test data with the project's own writers, so that the
// fuzzers start from files that read. Run from the source tree's top:
//   cmake --build build/fuzz --target liversim_fuzz_make_seeds
//   build/fuzz/tests/fuzz/liversim_fuzz_make_seeds tests/fuzz/corpus
// (any build tree will do). The seeds are committed; this is how they were made.

#include "liversim/meshing/surface_import.h"
#include "liversim/scenario/scenario.h"
#include "liversim/sessions/session_store.h"
#include "liversim/storage/sqlite_session_store.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gmsh.h>
#include <sqlite3.h>

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace liversim;

namespace {

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot be read");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& file, std::string_view bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out.flush()) throw std::runtime_error(file.string() + ": cannot be written");
  std::printf("%s (%zu bytes)\n", file.c_str(), bytes.size());
}

void write_bytes(const fs::path& file, const std::vector<std::uint8_t>& bytes) {
  write_bytes(file, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

std::string base64(std::string_view bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t group = static_cast<std::uint8_t>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) group |= static_cast<std::uint8_t>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) group |= static_cast<std::uint8_t>(bytes[i + 2]);
    out += kDigits[(group >> 18) & 63];
    out += kDigits[(group >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(group >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[group & 63] : '=';
  }
  return out;
}

// ---- trace chunks

ServoFrame frame(double t, std::uint32_t buttons) {
  ServoFrame f;
  f.time_s = t;
  f.sample.position_mm = {1.5 * t, -2.0, 30.0 + t};
  f.sample.velocity_mm_per_s = {0.25, 0.0, -1.0};
  f.force_n = {0.0, 0.125 * t, -0.5};
  f.sample.buttons = buttons;
  return f;
}

void trace_seeds(const fs::path& out) {
  write_bytes(out / "frames-none.bin", encode_frame_chunk({}));
  const std::vector<ServoFrame> frames = {frame(0.0, 0), frame(0.001, 1), frame(0.002, 3)};
  write_bytes(out / "frames-three.bin", encode_frame_chunk(frames));

  std::vector<SimulationInput> inputs(5);
  inputs[0].kind = SimulationInput::Kind::tool;
  Tool forceps;
  forceps.kind = ToolKind::forceps;
  forceps.pose.origin_m = {0.01, 0.02, 0.1};
  forceps.jaw_opening = 0.5;
  inputs[0].tool = forceps;
  inputs[1].kind = SimulationInput::Kind::springs;
  inputs[1].springs = {{12, {0.0, 0.01, 0.02}, 50.0, 0.5}, {40, {0.0, 0.0, 0.0}, 20.0, 0.0}};
  inputs[2].kind = SimulationInput::Kind::cycle;
  inputs[2].steps = 3;
  inputs[2].check_energy = true;
  inputs[2].servo_time_s = 0.004;
  inputs[3].kind = SimulationInput::Kind::tool;  // the tool taken away
  inputs[4].kind = SimulationInput::Kind::cycle;
  inputs[4].steps = 1;
  write_bytes(out / "inputs-every-kind.bin", encode_input_chunk(inputs));
  write_bytes(out / "inputs-none.bin", encode_input_chunk({}));
}

// ---- sessions databases

void sqlite_exec(sqlite3* db, const char* sql) {
  char* message = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string text = message ? message : "?";
    sqlite3_free(message);
    throw std::runtime_error(std::string(sql) + ": " + text);
  }
}

// The smallest pages SQLite allows, so that a seed is a few kilobytes, not 64.
std::string shrunk(const fs::path& file) {
  sqlite3* db = nullptr;
  if (sqlite3_open(file.c_str(), &db) != SQLITE_OK) throw std::runtime_error("cannot open");
  sqlite_exec(db, "PRAGMA journal_mode = DELETE");
  sqlite_exec(db, "PRAGMA page_size = 512");
  sqlite_exec(db, "VACUUM");
  sqlite3_close(db);
  return read_bytes(file);
}

void session_seeds(const fs::path& out, const fs::path& data, const fs::path& scratch) {
  const fs::path file = scratch / "sessions.sqlite";
  fs::remove(file);
  {
    SqliteSessionStore store(file);
    SessionStart start;
    start.trainee = "trainee-a";
    start.scenario_title = "Palpation";
    start.scenario_text = read_bytes(data / "scenario-small-resection.json");
    start.device = "mouse";
    start.started_unix_ms = 1700000000000;
    start.mapping = WorkspaceMapping{};
    start.replay = ReplaySetup{std::nullopt, "/scenarios", {}, 6.75e-4};
    const std::int64_t complete = store.begin_session(start);
    store.append_frames(complete, std::vector<ServoFrame>{frame(0.0, 0), frame(0.001, 1)});
    store.append_frames(complete, std::vector<ServoFrame>{frame(0.002, 1)});
    SimulationInput cycle;
    cycle.steps = 2;
    cycle.servo_time_s = 0.0;
    store.append_inputs(complete, std::vector<SimulationInput>{cycle, cycle});
    store.append_events(
        complete, std::vector<SessionEvent>{{0.0, SessionEventKind::tool_selected, "forceps"},
                                            {0.001, SessionEventKind::grasp, ""},
                                            {0.002, SessionEventKind::lesion_marked, "1 2 3"}});
    store.commit();
    store.end_session(complete, 1700000001000, SessionServoFigures{});
    store.store_metrics(complete, std::vector<MetricValue>{{"peak_force_n", 1.25}});
    store.set_password_cost_for_testing(kCheapPasswordCostForTesting);
    const Instructor grader =
        store.add_instructor_account("instructor-b", "seed password", nullptr);
    store.store_grade(grader, complete,
                      SessionGrade{"instructor-b", 1700000002000, 80.0, "B", "good"});
    // The training centre's records: uploaded to one server; the fuzz target's server not reached.
    store.mark_uploaded(complete, "other-server", 1700000003000);
    store.note_upload_problem(complete, "fuzz-server", "the server was not reached");

    start.trainee = "trainee-c";
    start.mapping.reset();
    start.replay = ReplaySetup{4000, "", {IntegratorKind::backward_euler, 1e-3}};
    const std::int64_t left = store.begin_session(start);  // left recording: a writer killed
    store.append_frames(left, std::vector<ServoFrame>{frame(0.0, 0)});
    store.commit();
  }
  write_bytes(
      out / ("sessions-v" + std::to_string(SqliteSessionStore::kSchemaVersion) + "-written.sqlite"),
      shrunk(file));
  // Every earlier schema version, as written by that version (tests/data/storage/sessions-vN),
  // migrated on opening; not the recorded sessions there (hundreds of kilobytes each).
  for (const auto& entry : fs::directory_iterator(data / "storage")) {
    if (entry.path().extension() != ".sqlite" ||
        !entry.path().filename().string().starts_with("sessions-v"))
      continue;
    fs::copy_file(entry.path(), file, fs::copy_options::overwrite_existing);
    write_bytes(out / entry.path().filename(), shrunk(file));
  }
  fs::remove(file);
}

// ---- surface models: the test cube in every format, the first byte picking the format

void surface_seeds(const fs::path& out, const fs::path& data, const fs::path& scratch) {
  const auto& extensions = surface_file_extensions();
  const auto selector = [&](std::string_view extension) {
    for (std::size_t i = 0; i < extensions.size(); ++i)
      if (extensions[i] == extension) return std::string(1, static_cast<char>(i));
    throw std::runtime_error("no such extension");
  };
  for (const char* name : {"cube-40mm.obj", "cube-40mm-holed.obj"})
    write_bytes(out / (std::string(name)), selector(".obj") + read_bytes(data / name));

  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile((data / "cube-40mm.obj").string(),
                                           aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
  if (!scene) throw std::runtime_error(importer.GetErrorString());
  Assimp::Exporter exporter;
  const struct {
    const char* format;
    const char* extension;
    const char* seed;
  } formats[] = {{"stl", ".stl", "cube-ascii.stl"},  {"stlb", ".stl", "cube-binary.stl"},
                 {"ply", ".ply", "cube-ascii.ply"},  {"plyb", ".ply", "cube-binary.ply"},
                 {"gltf2", ".gltf", "cube.gltf"},    {"glb2", ".glb", "cube.glb"},
                 {"fbxa", ".fbx", "cube-ascii.fbx"}, {"fbx", ".fbx", "cube-binary.fbx"},
                 {"3ds", ".3ds", "cube.3ds"}};
  for (const auto& f : formats) {
    const fs::path file = scratch / (std::string("cube") + f.extension);
    if (exporter.Export(scene, f.format, file.string()) != aiReturn_SUCCESS)
      throw std::runtime_error(std::string(f.format) + ": " + exporter.GetErrorString());
    std::string bytes = read_bytes(file);
    if (std::string_view(f.format) == "gltf2") {
      // The buffer goes into the file as a data URI: a fuzzed input is one file.
      const std::string uri = "\"cube.bin\"";
      const auto at = bytes.find(uri);
      if (at == std::string::npos) throw std::runtime_error("gltf2: no buffer uri");
      bytes.replace(at, uri.size(),
                    "\"data:application/octet-stream;base64," +
                        base64(read_bytes(scratch / "cube.bin")) + "\"");
    }
    write_bytes(out / f.seed, selector(f.extension) + bytes);
  }
}

// ---- Gmsh meshes: the test cube written by Gmsh itself in the binary and ASCII variants

void msh_seeds(const fs::path& out, const fs::path& data, const fs::path& scratch) {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::open((data / "cube_v4.msh").string());
  const struct {
    double version;
    int binary;
    const char* seed;
  } variants[] = {{2.2, 1, "cube_v2_binary.msh"}, {4.1, 1, "cube_v41_binary.msh"}};
  for (const auto& v : variants) {
    gmsh::option::setNumber("Mesh.MshFileVersion", v.version);
    gmsh::option::setNumber("Mesh.Binary", v.binary);
    gmsh::option::setNumber("Mesh.SaveAll", 1);
    const fs::path file = scratch / v.seed;
    gmsh::write(file.string());
    write_bytes(out / v.seed, read_bytes(file));
  }
  gmsh::finalize();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CORPUS_FOLDER  (tests/fuzz/corpus)\n", argv[0]);
    return 2;
  }
  try {
    const fs::path corpus = argv[1];
    const fs::path data = corpus / ".." / ".." / "data";
    const fs::path scratch = fs::temp_directory_path() / "liversim-fuzz-seeds";
    fs::create_directories(scratch);
    trace_seeds(corpus / "trace_chunks");
    session_seeds(corpus / "session_db", data, scratch);
    surface_seeds(corpus / "surface_import", data, scratch);
    msh_seeds(corpus / "mesh_msh", data, scratch);
    fs::remove_all(scratch);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "liversim_fuzz_make_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
