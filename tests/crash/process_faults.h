#pragma once
// Faults the crash tests give a real program: its standard output and error to files, a full disk
// (a tiny tmpfs in a user and mount namespace), and its file system turning read-only under it (a
// seccomp supervisor of its writes).
#include "crash_support.h"

#include <fcntl.h>
#include <linux/audit.h>
#include <linux/filter.h>
#include <linux/seccomp.h>
#include <poll.h>
#include <spawn.h>
#include <sys/ioctl.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace liversim::crash {

namespace fs = std::filesystem;

inline std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Starts `argv` with stdout and stderr to files of `folder`.
inline pid_t spawn(const std::vector<std::string>& arguments, const fs::path& folder) {
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

// Whether this process may make a user and mount namespace (unshare -rm).
inline std::optional<std::string> namespaces_unavailable() {
  const fs::path folder = fresh_folder("unshare-probe");
  const pid_t probe = spawn({"unshare", "-rm", "true"}, folder);
  if (probe <= 0) return "unshare cannot be run";
  if (wait_for(probe) != 0) return "unshare -rm fails here: " + read_text(folder / "stderr.txt");
  return std::nullopt;
}

// Waits until `writer` (its stderr in folder/stderr.txt) has committed `frames` frames to the
// first session of `database`; what it committed. If it has not within `patience`, it is killed
// and the test fails with its stderr.
inline std::optional<std::int64_t> wait_until_recording(pid_t writer, const fs::path& database,
                                                        std::int64_t frames,
                                                        std::chrono::seconds patience,
                                                        const fs::path& folder) {
  const std::optional<std::int64_t> committed = wait_for_committed(database, frames, patience);
  if (committed && *committed >= frames) return committed;
  kill(writer, SIGKILL);
  wait_for(writer);
  ADD_FAILURE() << "no session recorded (" << committed.value_or(0) << " of " << frames
                << " frames committed): " << read_text(folder / "stderr.txt");
  return std::nullopt;
}

// Runs `arguments` with `disk` a tmpfs of `size_kib` KiB (a full disk once that is written),
// stdout and stderr to files of `folder`, then writes its exit code to folder/rc and copies the
// files `disk/NAME*` of `database_name` to folder/kept, which outlives the namespace. The shell's
// own exit code (not 0: the tmpfs could not be made).
inline int run_on_a_small_disk(const std::vector<std::string>& arguments, const fs::path& folder,
                               const fs::path& disk, const std::string& database_name,
                               int size_kib) {
  fs::create_directories(disk);
  fs::create_directories(folder / "kept");
  std::string command = "mount -t tmpfs -o size=" + std::to_string(size_kib) + "k tmpfs '" +
                        disk.string() + "' || exit 90; ";
  for (const std::string& argument : arguments) command += "'" + argument + "' ";
  command += "; echo $? > '" + (folder / "rc").string() + "'; cp '" + disk.string() + "'/" +
             database_name + "* '" + (folder / "kept").string() + "'/";
  const pid_t shell = spawn({"unshare", "-rm", "sh", "-c", command}, folder);
  return shell > 0 ? wait_for(shell) : 127;
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

  // Starts `arguments` under the filter, stdout and stderr to files of `folder`, whose file system
  // is the one that turns read-only; -1 (and why in `problem`) when this kernel or sandbox does
  // not allow it.
  pid_t start(const std::vector<std::string>& arguments, const fs::path& folder,
              std::string& problem) {
    struct stat folder_status {};
    if (stat(folder.c_str(), &folder_status) != 0) {
      problem = "cannot stat " + folder.string();
      return -1;
    }
    device_ = folder_status.st_dev;
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

  // Whether the notified call touches the file system: a call on a descriptor does when its file
  // is on that file system (not a pipe, socket or eventfd; not a memfd, in which the GL driver
  // keeps its images; AddressSanitizer probes memory through a pipe), a call on a path always does.
  bool on_the_file_system(const seccomp_notif& request) const {
    const auto call = static_cast<long>(request.data.nr);
    const bool on_a_descriptor = call == SYS_write || call == SYS_writev || call == SYS_pwrite64 ||
                                 call == SYS_pwritev || call == SYS_pwritev2 ||
                                 call == SYS_ftruncate || call == SYS_fallocate;
    if (!on_a_descriptor) return true;
    const std::string link = "/proc/" + std::to_string(request.pid) + "/fd/" +
                             std::to_string(static_cast<int>(request.data.args[0]));
    struct stat target {};  // of the file the descriptor is open on (stat follows the link)
    const bool known = stat(link.c_str(), &target) == 0;
    // The answer holds only while the call is still waiting (the descriptor may be reused after).
    std::uint64_t id = request.id;
    if (ioctl(listener_, SECCOMP_IOCTL_NOTIF_ID_VALID, &id) != 0) return false;
    return known && target.st_dev == device_;
  }

  dev_t device_ = 0;  // the file system that turns read-only
  int listener_ = -1;
  std::atomic<bool> refuse_{false}, stop_{false};
  std::thread supervisor_;
};

}  // namespace liversim::crash
