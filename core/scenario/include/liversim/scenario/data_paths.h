#pragma once
// Where the files LiverSim ships beside its programs are found: the scenarios and the resources
// (tool models, icons). Installed, they are in share/liversim beside bin/; in a build tree, in the
// source tree the programs were built from. Both have the same layout (scenarios/, resources/).

#include <filesystem>

namespace liversim {

// LIVERSIM_DATA_DIR when set; else <program>/../share/liversim when it holds scenarios/; else
// the source tree. The folder may not exist (a moved build tree): callers name what is missing.
std::filesystem::path shipped_data_folder();
std::filesystem::path shipped_scenarios_folder();  // shipped_data_folder() / "scenarios"
std::filesystem::path shipped_resources_folder();  // shipped_data_folder() / "resources"

}  // namespace liversim
