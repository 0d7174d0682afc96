#pragma once
// The headless commands of liversim-cli. Each returns the process exit code and reports problems
// on stderr as "liversim-cli: error: ...".

#include <Eigen/Core>

#include <filesystem>
#include <optional>
#include <string>

namespace liversim::cli {

struct MeshSource {
  int tet_count = 5406;                       // built-in liver at this element count
  std::optional<std::filesystem::path> file;  // or a .inp / .msh file
  std::optional<std::string> fixed_set;       // node set of `file` held fixed
};

struct SimulateOptions {
  MeshSource mesh;
  double duration_s = 1.0;
  std::optional<int> node;  // default: a point on the anterior surface of the right lobe
  Eigen::Vector3d force_n{0.0, 0.1, 0.0};
  double load_radius_m = 0.01;  // the load is spread over surface nodes within this radius
  std::optional<std::filesystem::path> csv_output;
  double sample_interval_s = 0.01;
};

struct ScreenshotOptions {
  MeshSource mesh;
  std::filesystem::path output;
  int width = 1024;
  int height = 768;
};

int mesh_report(const MeshSource& mesh);
int simulate(const SimulateOptions& options);
int screenshot(const ScreenshotOptions& options);
// A short pull on the liver, released, with a screenshot of the deformed organ while pulled.
int demo(const ScreenshotOptions& options);

}  // namespace liversim::cli
