// A workstation's recording path without its window: a scripted device on a real servo thread
// at 1 kHz, its frames recorded to a sessions database until the process is killed (the storage
// test kills it with SIGKILL and checks what the database kept) or, with --seconds, for that long
// and then ended normally (the CLI tests read that session back).
//
// Usage: liversim_session_writer_child DATABASE [--seconds S] [--fresh]
// --fresh removes DATABASE first. Prints "epoch_ns N" (the servo clock's zero on the steady
// clock) and "session ID", then runs.
#include "liversim/haptics/emulated_devices.h"
#include "liversim/haptics/servo_loop.h"
#include "liversim/sessions/session_recorder.h"
#include "liversim/storage/sqlite_session_store.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <thread>

int main(int argc, char** argv) {
  using namespace liversim;
  double seconds = -1.0;  // < 0: until killed
  bool fresh = false;
  for (int i = 2; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--seconds") && i + 1 < argc)
      seconds = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--fresh"))
      fresh = true;
    else
      argc = 0;
  }
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s DATABASE [--seconds S] [--fresh]\n", argv[0]);
    return 2;
  }
  try {
    if (fresh)
      for (const char* suffix : {"", "-wal", "-shm"})
        std::filesystem::remove(std::string(argv[1]) + suffix);
    // A slow circle in the device's workspace, a minute long.
    std::vector<TrajectoryPoint> circle;
    for (int i = 0; i <= 600; ++i) {
      const double t = 0.1 * i;
      circle.push_back({t, Eigen::Vector3d(30.0 * std::cos(t), 30.0 * std::sin(t), 0.0),
                        static_cast<std::uint32_t>(i % 20 < 10)});
    }
    TrajectoryDevice device("Scripted circle", circle);
    SqliteSessionStore store(argv[1]);
    ServoLoop servo(device, ServoLoop::Options{});
    const auto epoch = std::chrono::steady_clock::now() -
                       std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                           std::chrono::duration<double>(servo.now_s()));
    SessionStart start{"Trainee A",   "Scripted circle", "{\"title\": \"Scripted circle\"}",
                       device.name(), 1'795'000'000'000, std::nullopt,
                       std::nullopt};
    SessionRecorder recorder(store, start,
                             [&](ServoFrame& frame) { return servo.next_logged_frame(frame); });
    servo.start();
    std::printf(
        "epoch_ns %lld\nsession %lld\n",
        static_cast<long long>(
            std::chrono::duration_cast<std::chrono::nanoseconds>(epoch.time_since_epoch()).count()),
        static_cast<long long>(recorder.session()));
    std::fflush(stdout);
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (recorder.error().empty() && (seconds < 0.0 || std::chrono::steady_clock::now() < end))
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (recorder.error().empty()) {
      servo.stop();
      if (recorder.finish(1'795'000'000'000 + static_cast<std::int64_t>(seconds * 1e3),
                          servo_figures(servo.stats(), servo.dropped_log_frames())))
        return 0;
    }
    std::fprintf(stderr, "%s\n", recorder.error().c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
