// liversim-cli: headless simulation, mesh reports and screenshots.
#include "cli_commands.h"

#include <CLI/CLI.hpp>

#include <iostream>

namespace {

void add_mesh_options(CLI::App& command, liversim::cli::MeshSource& mesh) {
  command.add_option("--tets", mesh.tet_count, "Element count of the built-in liver")
      ->check(CLI::Range(100, 2'000'000))
      ->capture_default_str();
  command.add_option("--mesh", mesh.file, "Tetrahedral mesh file (.inp or .msh) instead")
      ->check(CLI::ExistingFile);
  command.add_option("--fixed-set", mesh.fixed_set, "Node set of --mesh to hold fixed");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace liversim::cli;
  CLI::App app{"LiverSim headless tools: simulate the liver, report mesh quality, render images"};
  app.set_version_flag("--version", std::string("liversim-cli ") + LIVERSIM_VERSION);
  app.require_subcommand(1);

  MeshSource report_mesh;
  auto* report = app.add_subcommand("mesh-report", "Print the quality report of a mesh");
  add_mesh_options(*report, report_mesh);

  SimulateOptions sim;
  std::vector<double> force;
  auto* simulate_cmd = app.add_subcommand(
      "simulate", "Load a point of the liver for a while and print the point's displacement");
  add_mesh_options(*simulate_cmd, sim.mesh);
  simulate_cmd->add_option("--time", sim.duration_s, "Simulated time in seconds")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  simulate_cmd->add_option("--node", sim.node, "Loaded node (0-based; default: anterior point)")
      ->check(CLI::NonNegativeNumber);
  simulate_cmd->add_option("--force", force, "Load in newtons: FX FY FZ (default 0 0.1 0)")
      ->expected(3);
  simulate_cmd
      ->add_option("--load-radius", sim.load_radius_m,
                   "Spread the load over surface nodes within this radius (m)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  simulate_cmd->add_option("--output", sim.csv_output, "Write the displacement history as CSV");
  simulate_cmd->add_option("--sample-interval", sim.sample_interval_s, "CSV sample interval (s)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();

  ScreenshotOptions shot;
  auto* screenshot_cmd =
      app.add_subcommand("screenshot", "Render the default scene to a PNG (needs X or xvfb-run)");
  add_mesh_options(*screenshot_cmd, shot.mesh);
  screenshot_cmd->add_option("--output,-o", shot.output, "PNG file to write")->required();
  screenshot_cmd->add_option("--width", shot.width)->check(CLI::Range(16, 8192));
  screenshot_cmd->add_option("--height", shot.height)->check(CLI::Range(16, 8192));

  ScreenshotOptions demo_shot;
  demo_shot.output = "liversim-demo.png";
  auto* demo_cmd = app.add_subcommand(
      "demo", "Pull the liver for a short simulation, then write a screenshot of it");
  demo_cmd->add_option("--output,-o", demo_shot.output, "PNG file to write")->capture_default_str();

  try {
    app.parse(argc, argv);
    if (force.size() == 3) sim.force_n = {force[0], force[1], force[2]};
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  if (report->parsed()) return mesh_report(report_mesh);
  if (simulate_cmd->parsed()) return simulate(sim);
  if (screenshot_cmd->parsed()) return screenshot(shot);
  if (demo_cmd->parsed()) return demo(demo_shot);
  return 1;
}
