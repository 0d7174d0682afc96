// `liversim-cli record` end to end, and its crash safety: a recorded session read back; the
// recorder killed with SIGKILL mid-session (nothing committed is lost, the next run recovers); a
// real full disk (a tiny tmpfs in a user and mount namespace); the database's file system turning
// read-only mid-session. Runs the real binary; needs no display.
#include "crash_support.h"
#include "liversim/core/session_replay.h"
#include "liversim/storage/sqlite_session_store.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <linux/audit.h>
#include <linux/filter.h>
#include <linux/seccomp.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/ioctl.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace liversim {
namespace {

namespace fs = std::filesystem;

using crash::expect_frames_in_order;
using crash::wait_for;

// The test's folder (under the crash tests' output).
fs::path fresh_folder(const std::string& name) {
  return crash::fresh_folder("record-" + name);
}

// The probe pushed 10 mm (device; 15 mm in the scene) toward the liver from the device's home in
// front of it and moved across, with its button down, then back; then it rests there.
fs::path write_trajectory(const fs::path& folder) {
  const fs::path file = folder / "trajectory.txt";
  std::ofstream(file) << "# time_s x_mm y_mm z_mm buttons\n"
                         "0 0 0 0 0\n1 0 0 -10 1\n2 10 5 -10 1\n3 0 0 0 0\n600 0 0 0 0\n";
  return file;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Starts `argv` with stdout and stderr to files of `folder`.
pid_t spawn(const std::vector<std::string>& arguments, const fs::path& folder) {
  std::vector<std::string> all = arguments;
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 1, (folder / "stdout.txt").c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&files, 2, (folder / "stderr.txt").c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t child = 0;
  const int result = posix_spawnp(&child, argv[0], &files, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  return result == 0 ? child : -1;
}

std::vector<std::string> record_arguments(const fs::path& trajectory, const fs::path& database,
                                          double duration_s) {
  return {LIVERSIM_CLI, "record",     "--tets", "1000",       "--trajectory",
          trajectory,   "--database", database, "--duration", std::to_string(duration_s),
          "--tool",     "probe"};
}

TEST(CliRecord, RecordsACompleteSessionWithEveryServoFrameItsInputLogAndItsMetrics) {
  const fs::path folder = fresh_folder("complete");
  const fs::path database = folder / "sessions.sqlite";
  constexpr double kDurationS = 2.0;
  std::vector<std::string> arguments =
      record_arguments(write_trajectory(folder), database, kDurationS);
  arguments.insert(arguments.end(), {"--progress", "0.5", "--trainee", "Trainee B"});
  const pid_t cli = spawn(arguments, folder);
  ASSERT_GT(cli, 0);
  ASSERT_EQ(wait_for(cli), 0) << read_text(folder / "stderr.txt");
  const std::string out = read_text(folder / "stdout.txt");
  EXPECT_TRUE(std::regex_search(out, std::regex("elapsed [0-9.]+ s: [0-9]+ frames committed, "
                                                "VmRSS [0-9.]+ MiB, VmHWM [0-9.]+ MiB")))
      << out;
  EXPECT_NE(out.find("recorded session 1 (complete)"), std::string::npos) << out;

  SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
  EXPECT_EQ(store.integrity_check(), "ok");
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 1u);
  const SessionSummary& session = sessions[0];
  EXPECT_EQ(session.status, SessionStatus::complete);
  EXPECT_EQ(session.trainee, "Trainee B");
  EXPECT_EQ(session.scenario_title, "Free practice");
  EXPECT_EQ(session.device, "Scripted: trajectory.txt");
  ASSERT_TRUE(session.servo.has_value());
  ASSERT_TRUE(session.mapping.has_value());
  EXPECT_DOUBLE_EQ(session.mapping->scale, 1.5);  // the workstation's first-use mapping
  expect_frames_in_order(store, session);

  // Every servo tick of the session is a frame: as many as the servo's own rate over the time
  // the frames span (the servo's statistics lag by up to 50 ms), and that span is the duration
  // asked for, on the servo's clock.
  const std::vector<ServoFrame> frames = store.frames(session.id);
  const double span_s = frames.back().time_s - frames.front().time_s;
  const SessionServoFigures& servo = *session.servo;
  EXPECT_GT(servo.rate_hz, 500.0) << "a 1 kHz servo";
  EXPECT_GE(span_s, kDurationS - 0.02);
  EXPECT_NEAR(static_cast<double>(session.frame_count), servo.rate_hz * span_s,
              0.05 * servo.rate_hz * span_s);
  EXPECT_NEAR(static_cast<double>(session.frame_count + servo.dropped_frames),
              static_cast<double>(servo.ticks), 0.06 * servo.rate_hz);
  EXPECT_EQ(servo.dropped_frames, 0u);

  // Replayable: its scene and input log; the tool chosen; the metrics stored at the end.
  const std::optional<ReplaySetup> replay_setup = store.replay_setup(session.id);
  ASSERT_TRUE(replay_setup.has_value());
  EXPECT_EQ(replay_setup->built_in_liver_tets, 1000);
  SessionReplay replay(replay_scene(*replay_setup, store.scenario_text(session.id)),
                       store.inputs(session.id));
  EXPECT_TRUE(replay.advance_to(replay.end_s()));
  EXPECT_GE(replay.end_s() - replay.begin_s(), kDurationS - 0.1) << "the whole session replays";
  const std::vector<SessionEvent> events = store.events(session.id);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.front().kind, SessionEventKind::tool_selected);
  EXPECT_EQ(events.front().detail, "probe");
  std::vector<std::string> metric_names;
  for (const MetricValue& metric : store.metrics(session.id)) metric_names.push_back(metric.name);
  for (const char* expected :
       {"task_time_s", "path_length_mm", "peak_force_n", "tissue_damage_mm3"})
    EXPECT_NE(std::find(metric_names.begin(), metric_names.end(), expected), metric_names.end())
        << expected;
}

TEST(CliRecordCrash, KilledMidSessionItLosesNothingCommittedAndTheNextRunRecovers) {
  const fs::path folder = fresh_folder("killed");
  const fs::path database = folder / "sessions.sqlite";
  const fs::path trajectory = write_trajectory(folder);
  const pid_t cli = spawn(record_arguments(trajectory, database, 600.0), folder);
  ASSERT_GT(cli, 0);
  const std::optional<std::int64_t> before =
      crash::wait_for_committed(database, 500, std::chrono::seconds(60));
  ASSERT_TRUE(before && *before >= 500)
      << "no session recorded: " << read_text(folder / "stderr.txt");
  crash::kill_and_expect_recovery(cli, database, *before);
  if (HasFatalFailure()) return;
  const pid_t next = spawn(record_arguments(trajectory, database, 1.0), folder);
  ASSERT_GT(next, 0);
  ASSERT_EQ(wait_for(next), 0) << read_text(folder / "stderr.txt");
  SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
  EXPECT_EQ(store.integrity_check(), "ok");
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 2u);
  EXPECT_EQ(sessions[0].status, SessionStatus::incomplete);
  EXPECT_EQ(sessions[1].status, SessionStatus::complete);
  EXPECT_GT(sessions[1].frame_count, 0);
  EXPECT_FALSE(store.metrics(sessions[1].id).empty());
}

TEST(CliRecordCrash, SigtermEndsTheSessionNormally) {
  const fs::path folder = fresh_folder("sigterm");
  const fs::path database = folder / "sessions.sqlite";
  const pid_t cli = spawn(record_arguments(write_trajectory(folder), database, 600.0), folder);
  ASSERT_GT(cli, 0);
  const std::optional<std::int64_t> before =
      crash::wait_for_committed(database, 200, std::chrono::seconds(60));
  ASSERT_TRUE(before && *before >= 200) << read_text(folder / "stderr.txt");
  ASSERT_EQ(kill(cli, SIGTERM), 0);
  ASSERT_EQ(wait_for(cli), 0) << read_text(folder / "stderr.txt");
  EXPECT_NE(read_text(folder / "stdout.txt").find("(complete, ended by SIGTERM)"),
            std::string::npos);
  SqliteSessionStore store(database, SqliteSessionStore::Access::read_only);
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].status, SessionStatus::complete);
  EXPECT_GE(sessions[0].frame_count, *before);
  EXPECT_FALSE(store.metrics(sessions[0].id).empty());
}

// The frames committed as the last progress line of `record --progress` says; 0 without one.
std::int64_t last_committed(const std::string& progress) {
  const std::regex line("elapsed [0-9.]+ s: ([0-9]+) frames committed");
  std::int64_t committed = 0;
  for (auto match = std::sregex_iterator(progress.begin(), progress.end(), line);
       match != std::sregex_iterator(); ++match)
    committed = std::stoll((*match)[1].str());
  return committed;
}

// Whether this process may make a user and mount namespace (unshare -rm).
std::optional<std::string> namespaces_unavailable() {
  const fs::path folder = fresh_folder("unshare-probe");
  const pid_t probe = spawn({"unshare", "-rm", "true"}, folder);
  if (probe <= 0) return "unshare cannot be run";
  if (wait_for(probe) != 0) return "unshare -rm fails here: " + read_text(folder / "stderr.txt");
  return std::nullopt;
}

TEST(CliRecordCrash, AFullDiskStopsTheRecordingWithTheFileNamedAndKeepsWhatWasCommitted) {
  if (const auto why = namespaces_unavailable()) GTEST_SKIP() << *why;
  const fs::path folder = fresh_folder("full-disk");
  const fs::path disk = folder / "disk";  // a 256 KiB tmpfs inside the namespace
  const fs::path kept = folder / "kept";  // the database copied out after the run
  fs::create_directories(disk);
  fs::create_directories(kept);
  const fs::path database = disk / "sessions.sqlite";
  std::vector<std::string> arguments = record_arguments(write_trajectory(folder), database, 60.0);
  arguments.insert(arguments.end(), {"--progress", "0.05"});  // what it has committed, said
  std::string command = "mount -t tmpfs -o size=256k tmpfs '" + disk.string() + "' || exit 90; ";
  for (const std::string& argument : arguments) command += "'" + argument + "' ";
  command += "; echo $? > '" + (folder / "rc").string() + "'; cp '" + disk.string() +
             "'/sessions.sqlite* '" + kept.string() + "'/";
  const pid_t shell = spawn({"unshare", "-rm", "sh", "-c", command}, folder);
  ASSERT_GT(shell, 0);
  ASSERT_EQ(wait_for(shell), 0) << read_text(folder / "stderr.txt");
  const std::string stderr_text = read_text(folder / "stderr.txt");
  EXPECT_EQ(std::stoi(read_text(folder / "rc")), 1) << stderr_text;
  EXPECT_NE(stderr_text.find(database.string()), std::string::npos) << stderr_text;
  EXPECT_NE(stderr_text.find("failed: the disk or the database is full"), std::string::npos)
      << stderr_text;
  EXPECT_NE(stderr_text.find("what was committed before is kept"), std::string::npos);

  SqliteSessionStore store(kept / "sessions.sqlite");
  EXPECT_EQ(store.integrity_check(), "ok");
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].status, SessionStatus::incomplete);
  EXPECT_GT(sessions[0].frame_count, 0) << "nothing was committed before the disk was full";
  EXPECT_GE(sessions[0].frame_count, last_committed(read_text(folder / "stdout.txt")))
      << "frames committed before the disk was full were lost";
  expect_frames_in_order(store, sessions[0]);
}

// A file system turning read-only under a running writer: the kernel refuses a remount
// read-only while a file on it is open for writing (EBUSY), so it happens only by the kernel's
// own doing (errors=remount-ro after a disk error). Its answer, EROFS to every write, is given
// here by a seccomp supervisor of the child's writes, which lets them through until `refuse`.
class ReadOnlyFileSystem {
 public:
  ReadOnlyFileSystem() = default;
  ~ReadOnlyFileSystem() {
    stop_ = true;
    if (supervisor_.joinable()) supervisor_.join();
    if (listener_ >= 0) close(listener_);
  }

  // Starts `arguments` under the filter, stdout and stderr to files of `folder`; -1 (and why in
  // `problem`) when this kernel or sandbox does not allow it.
  pid_t start(const std::vector<std::string>& arguments, const fs::path& folder,
              std::string& problem) {
    std::vector<std::string> all = arguments;
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    const std::string out = (folder / "stdout.txt").string();
    const std::string err = (folder / "stderr.txt").string();
    int channel[2];
    if (socketpair(AF_UNIX, SOCK_STREAM, 0, channel) != 0) {
      problem = "no socket pair";
      return -1;
    }
    const std::vector<sock_filter> filter = write_filter();
    const pid_t child = fork();
    if (child == 0) {  // async-signal-safe calls only until exec
      close(channel[0]);
      const int out_fd = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int err_fd = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(out_fd, 1);
      dup2(err_fd, 2);
      sock_fprog program{static_cast<unsigned short>(filter.size()),
                         const_cast<sock_filter*>(filter.data())};
      if (prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0) _exit(120);
      const long listener =
          syscall(SYS_seccomp, SECCOMP_SET_MODE_FILTER, SECCOMP_FILTER_FLAG_NEW_LISTENER, &program);
      if (listener < 0) _exit(121);
      if (!send_fd(channel[1], static_cast<int>(listener))) _exit(122);
      close(static_cast<int>(listener));
      close(channel[1]);
      execvp(argv[0], argv.data());
      _exit(127);
    }
    close(channel[1]);
    if (child < 0) {
      close(channel[0]);
      problem = "fork failed";
      return -1;
    }
    listener_ = receive_fd(channel[0]);
    close(channel[0]);
    if (listener_ < 0) {
      const int code = wait_for(child);
      problem =
          "seccomp user notification is not available (child exit " + std::to_string(code) + ")";
      return -1;
    }
    supervisor_ = std::thread([this] { supervise(); });
    return child;
  }

  void make_read_only() { refuse_ = true; }

 private:
  // The calls that write a file, a file system's contents or its names (not the standard output
  // and error): notified to the supervisor.
  static std::vector<sock_filter> write_filter() {
    const auto load = [](std::uint32_t offset) {
      return sock_filter BPF_STMT(BPF_LD | BPF_W | BPF_ABS, offset);
    };
    const auto ret = [](std::uint32_t value) {
      return sock_filter BPF_STMT(BPF_RET | BPF_K, value);
    };
    const auto nr = offsetof(seccomp_data, nr);
    const auto arg_low = [](int n) {
      return static_cast<std::uint32_t>(offsetof(seccomp_data, args) + 8 * n);
    };
    constexpr std::uint32_t kWriteFlags = O_WRONLY | O_RDWR | O_CREAT | O_TRUNC;
    std::vector<sock_filter> f;
    f.push_back(load(offsetof(seccomp_data, arch)));
    f.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, AUDIT_ARCH_X86_64, 1, 0));
    f.push_back(ret(SECCOMP_RET_ALLOW));
    f.push_back(load(nr));
    // Always notified.
    for (const long call :
         {SYS_pwrite64, SYS_pwritev, SYS_pwritev2, SYS_ftruncate, SYS_fallocate, SYS_unlink,
          SYS_unlinkat, SYS_rename, SYS_renameat, SYS_renameat2, SYS_mkdir, SYS_mkdirat}) {
      f.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, static_cast<std::uint32_t>(call), 0, 1));
      f.push_back(ret(SECCOMP_RET_USER_NOTIF));
    }
    // write and writev to descriptors above 2.
    for (const long call : {SYS_write, SYS_writev}) {
      f.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, static_cast<std::uint32_t>(call), 0, 4));
      f.push_back(load(arg_low(0)));
      f.push_back(BPF_JUMP(BPF_JMP | BPF_JGT | BPF_K, 2, 0, 1));
      f.push_back(ret(SECCOMP_RET_USER_NOTIF));
      f.push_back(ret(SECCOMP_RET_ALLOW));
    }
    // open and openat for writing.
    for (const auto& [call, flags_arg] : {std::pair{SYS_open, 1}, std::pair{SYS_openat, 2}}) {
      f.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, static_cast<std::uint32_t>(call), 0, 4));
      f.push_back(load(arg_low(flags_arg)));
      f.push_back(BPF_JUMP(BPF_JMP | BPF_JSET | BPF_K, kWriteFlags, 0, 1));
      f.push_back(ret(SECCOMP_RET_USER_NOTIF));
      f.push_back(ret(SECCOMP_RET_ALLOW));
    }
    f.push_back(ret(SECCOMP_RET_ALLOW));
    return f;
  }

  // A message of one byte carrying one file descriptor (SCM_RIGHTS): how the child hands the
  // filter's listener to its supervisor.
  struct FdMessage {
    char byte = 0;
    iovec data{&byte, 1};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))] = {};
    msghdr message{};
    FdMessage() {
      message.msg_iov = &data;
      message.msg_iovlen = 1;
      message.msg_control = control;
      message.msg_controllen = sizeof(control);
    }
    FdMessage(const FdMessage&) = delete;
    FdMessage& operator=(const FdMessage&) = delete;
  };
  static bool send_fd(int socket, int fd) {  // async-signal-safe: the child calls it
    FdMessage sent;
    cmsghdr* header = CMSG_FIRSTHDR(&sent.message);
    header->cmsg_level = SOL_SOCKET;
    header->cmsg_type = SCM_RIGHTS;
    header->cmsg_len = CMSG_LEN(sizeof(int));
    std::memcpy(CMSG_DATA(header), &fd, sizeof(int));
    return sendmsg(socket, &sent.message, 0) == 1;
  }
  static int receive_fd(int socket) {
    FdMessage received;
    if (recvmsg(socket, &received.message, 0) != 1) return -1;
    const cmsghdr* header = CMSG_FIRSTHDR(&received.message);
    if (header == nullptr || header->cmsg_type != SCM_RIGHTS) return -1;
    int fd = -1;
    std::memcpy(&fd, CMSG_DATA(header), sizeof(int));
    return fd;
  }

  // Lets each write through (SECCOMP_USER_NOTIF_FLAG_CONTINUE) until read-only, then refuses it
  // with EROFS, until the child has gone.
  void supervise() {
    seccomp_notif_sizes sizes{};
    if (syscall(SYS_seccomp, SECCOMP_GET_NOTIF_SIZES, 0, &sizes) != 0) return;
    std::vector<std::byte> request_bytes(
        std::max<std::size_t>(sizes.seccomp_notif, sizeof(seccomp_notif)));
    std::vector<std::byte> response_bytes(
        std::max<std::size_t>(sizes.seccomp_notif_resp, sizeof(seccomp_notif_resp)));
    auto* request = reinterpret_cast<seccomp_notif*>(request_bytes.data());
    auto* response = reinterpret_cast<seccomp_notif_resp*>(response_bytes.data());
    while (!stop_) {
      pollfd ready{listener_, POLLIN, 0};
      if (poll(&ready, 1, 50) <= 0) continue;
      if (ready.revents & (POLLHUP | POLLERR)) return;  // the child has gone
      std::fill(request_bytes.begin(), request_bytes.end(), std::byte{0});
      if (ioctl(listener_, SECCOMP_IOCTL_NOTIF_RECV, request) != 0) continue;
      std::fill(response_bytes.begin(), response_bytes.end(), std::byte{0});
      response->id = request->id;
      if (refuse_ && on_the_file_system(*request)) {
        response->error = -EROFS;
      } else {
        response->flags = SECCOMP_USER_NOTIF_FLAG_CONTINUE;
      }
      ioctl(listener_, SECCOMP_IOCTL_NOTIF_SEND, response);
    }
  }

  // Whether the notified call touches the file system: a call on a descriptor does when it names
  // a file (a pipe, socket or eventfd stays writable on a read-only file system; AddressSanitizer
  // probes memory through a pipe), a call on a path always does.
  bool on_the_file_system(const seccomp_notif& request) const {
    const auto call = static_cast<long>(request.data.nr);
    const bool on_a_descriptor = call == SYS_write || call == SYS_writev || call == SYS_pwrite64 ||
                                 call == SYS_pwritev || call == SYS_pwritev2 ||
                                 call == SYS_ftruncate || call == SYS_fallocate;
    if (!on_a_descriptor) return true;
    const std::string link = "/proc/" + std::to_string(request.pid) + "/fd/" +
                             std::to_string(static_cast<int>(request.data.args[0]));
    char target[512] = {};
    const ssize_t length = readlink(link.c_str(), target, sizeof(target) - 1);
    // The answer holds only while the call is still waiting (the descriptor may be reused after).
    std::uint64_t id = request.id;
    if (ioctl(listener_, SECCOMP_IOCTL_NOTIF_ID_VALID, &id) != 0) return false;
    return length > 0 && target[0] == '/';
  }

  int listener_ = -1;
  std::atomic<bool> refuse_{false}, stop_{false};
  std::thread supervisor_;
};

TEST(CliRecordCrash, AFileSystemTurnedReadOnlyStopsTheRecordingWithTheFileNamed) {
#if !defined(__x86_64__)
  GTEST_SKIP() << "the seccomp filter of this test is written for x86-64";
#endif
  const fs::path folder = fresh_folder("read-only");
  const fs::path database = folder / "sessions.sqlite";
  ReadOnlyFileSystem file_system;
  std::string problem;
  const pid_t cli = file_system.start(record_arguments(write_trajectory(folder), database, 60.0),
                                      folder, problem);
  if (cli < 0) GTEST_SKIP() << problem;
  const std::optional<std::int64_t> before =
      crash::wait_for_committed(database, 300, std::chrono::seconds(60));
  if (!before || *before < 300) {
    kill(cli, SIGKILL);
    wait_for(cli);
    FAIL() << "no session recorded: " << read_text(folder / "stderr.txt");
  }
  file_system.make_read_only();
  EXPECT_EQ(wait_for(cli), 1);
  const std::string stderr_text = read_text(folder / "stderr.txt");
  EXPECT_NE(stderr_text.find(database.string()), std::string::npos) << stderr_text;
  EXPECT_NE(stderr_text.find("the file is read-only: its file system was made read-only"),
            std::string::npos)
      << stderr_text;
  EXPECT_NE(stderr_text.find("what was committed before is kept"), std::string::npos);

  SqliteSessionStore store(database);
  EXPECT_EQ(store.integrity_check(), "ok");
  const std::vector<SessionSummary> sessions = store.sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].status, SessionStatus::incomplete);
  EXPECT_GE(sessions[0].frame_count, *before) << "frames committed before were lost";
  expect_frames_in_order(store, sessions[0]);
}

}  // namespace
}  // namespace liversim
