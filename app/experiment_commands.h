#pragma once
// liversim-cli experiment creep|pull|timing: the seed's three experiments (seed §4.2–4.4) on the
// built-in liver, written as CSV, PNG plots and a markdown table (docs/seed-experiments.md).

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace liversim::cli {

// What every experiment takes: the liver, and the time integrator that goes into the model.
struct ExperimentModelOptions {
  int tet_count = 5406;                           // built-in liver at this element count
  std::string integrator = "central-difference";  // a name of integrator_from_name
  double dt_s = 0.0;  // integrator step; 0: the stable step (explicit schemes only)
};

struct CreepExperimentOptions {
  ExperimentModelOptions model;
  double peak_force_n = 0.63;
  double ramp_time_s = 2.0;
  double duration_s = 4.0;
  double sample_interval_s = 0.01;
  double load_radius_m = 0.02;
  bool viscoelastic = false;  // the assumed SLS of material-test instead of the elastic tissue
  std::optional<std::filesystem::path> csv_output, ratio_csv_output;
  std::optional<std::filesystem::path> plot_output, ratio_plot_output;
  // The marked point's displacement every quarter of the ramp, as a markdown table.
  std::optional<std::filesystem::path> table_output;
};

struct PullExperimentOptions {
  ExperimentModelOptions model;
  std::vector<double> forces_n{0.93, 1.65, 2.96};
  double load_radius_m = 0.02;
  double residual_tolerance = 1e-3;
  double max_time_s = 30.0;
  std::string attachment = "patch";  // "patch": point loads; "forceps": the forceps' hold
  std::optional<std::filesystem::path> csv_output, history_csv_output, plot_output;
  std::optional<std::filesystem::path> table_output;  // the table printed, as a markdown file
};

struct TimingExperimentOptions {
  std::string integrator = "central-difference";
  double dt_s = 0.002;  // the seed's: both the frame and the integrator's requested step
  std::vector<int> tet_counts{3841, 5406, 7312, 9371, 10583};
  double force_n = 0.75;
  double simulated_s = 1.0;
  std::optional<std::filesystem::path> csv_output, plot_output;
  std::optional<std::filesystem::path> table_output;  // the table printed, as a markdown file
};

// Adds `experiment` with its subcommands creep, pull and timing to the app. After parsing, the
// returned function runs the experiment asked for and returns its exit code (nothing when
// `experiment` was not on the command line).
std::function<std::optional<int>()> add_experiment_command(CLI::App& app);

int creep_experiment(const CreepExperimentOptions& options);
int pull_experiment(const PullExperimentOptions& options);
int timing_experiment(const TimingExperimentOptions& options);

}  // namespace liversim::cli
