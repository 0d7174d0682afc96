#include "liversim/scenario/data_paths.h"

#include <cstdlib>
#include <system_error>

namespace liversim {

std::filesystem::path shipped_data_folder() {
  if (const char* set = std::getenv("LIVERSIM_DATA_DIR"); set != nullptr && *set != '\0')
    return set;
  std::error_code error;
  const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) {
    const std::filesystem::path installed =
        program.parent_path().parent_path() / "share" / "liversim";
    if (std::filesystem::is_directory(installed / "scenarios", error)) return installed;
  }
  return LIVERSIM_SOURCE_DATA_DIR;
}

std::filesystem::path shipped_scenarios_folder() {
  return shipped_data_folder() / "scenarios";
}

std::filesystem::path shipped_resources_folder() {
  return shipped_data_folder() / "resources";
}

}  // namespace liversim
