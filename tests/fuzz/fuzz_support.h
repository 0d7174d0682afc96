#pragma once
// Shared by the fuzz targets (docs/fuzzing.md): a scratch folder for the readers that take a file
// name, and the check that turns a broken promise of the API into a crash the fuzzer reports.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

namespace liversim::fuzz {

// A folder of this process's own under TMPDIR (the readers take file names; TMPDIR=/dev/shm keeps
// the files in memory), removed when the process ends normally.
class ScratchFolder {
 public:
  ScratchFolder()
      : path_(std::filesystem::temp_directory_path() /
              ("liversim-fuzz-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline const std::filesystem::path& scratch_folder() {
  static const ScratchFolder folder;
  return folder.path();
}

// The input as the file `name` in the scratch folder, replacing what was there.
inline std::filesystem::path write_scratch_file(std::string_view name, const std::uint8_t* data,
                                                std::size_t size) {
  const std::filesystem::path file = scratch_folder() / std::string(name);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out.flush()) {
    std::fprintf(stderr, "fuzz: cannot write the scratch file %s\n", file.c_str());
    std::abort();  // not a finding: the harness itself cannot run
  }
  return file;
}

// A promise of the API the input broke (a reading that is neither a result nor a documented
// error): abort, which the fuzzer reports as a crash with this input.
[[noreturn]] inline void broken_promise(const char* what, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: fuzz check failed: %s\n", file, line, what);
  std::abort();
}

}  // namespace liversim::fuzz

#define LIVERSIM_FUZZ_CHECK(condition)                                                  \
  do {                                                                                  \
    if (!(condition)) ::liversim::fuzz::broken_promise(#condition, __FILE__, __LINE__); \
  } while (false)
