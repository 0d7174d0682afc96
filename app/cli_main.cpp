// liversim-cli: headless simulation, mesh reports and screenshots.
#include "bench_command.h"
#include "cli_commands.h"
#include "cut_bench_command.h"
#include "experiment_commands.h"
#include "record_command.h"
#include "render_bench_command.h"
#include "server_command.h"
#include "servo_bench_command.h"
#include "sessions_command.h"
#include "study_command.h"

#include <CLI/CLI.hpp>

#include <iostream>
#include <map>

namespace {

void add_mesh_options(CLI::App& command, liversim::cli::MeshSource& mesh) {
  command
      .add_option("--tets", mesh.tet_count,
                  "Element count of the built-in liver, or the one --surface is meshed at")
      ->check(CLI::Range(100, 2'000'000))
      ->capture_default_str();
  command.add_option("--mesh", mesh.file, "Tetrahedral mesh file (.inp or .msh) instead")
      ->check(CLI::ExistingFile);
  command.add_option("--fixed-set", mesh.fixed_set, "Node set of --mesh to hold fixed");
  command
      .add_option("--scenario", mesh.scenario,
                  "Scenario file (scenarios/*.json): its organ, tissue, lesions and integrator")
      ->check(CLI::ExistingFile);
  command
      .add_option("--surface", mesh.surface,
                  "Closed surface model (.obj, .stl, .ply, .gltf, .glb, .fbx, .3ds) instead, "
                  "tetrahedralised by Gmsh at about --tets elements; nothing is held fixed")
      ->check(CLI::ExistingFile);
  command.add_option("--length-unit", mesh.length_unit,
                     "Unit of the --surface file's lengths: mm, cm or m (required with --surface)");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace liversim::cli;
  CLI::App app{
      "LiverSim headless tools: simulate the liver, report mesh quality, render images, "
      "test the tissue law"};
  app.set_version_flag("--version", std::string("liversim-cli ") + LIVERSIM_VERSION);
  app.require_subcommand(1);

  MeshReportOptions report_options;
  auto* report = app.add_subcommand("mesh-report", "Print the quality report of a mesh");
  add_mesh_options(*report, report_options.mesh);
  report->add_option("--write-surface", report_options.surface_output,
                     "Also write the mesh's boundary as a Wavefront OBJ in millimetres (what "
                     "--surface reads with --length-unit mm)");
  report->add_option("--table", report_options.table_output,
                     "Also append the report as a row of this markdown table (its header first "
                     "when the file is new; docs/mesh-quality.md)");

  std::vector<std::filesystem::path> scenario_files;
  auto* validate_cmd = app.add_subcommand(
      "validate",
      "Check scenario files; print each error with the field's path, its value and what is "
      "expected (exit status 1 when any file is invalid)");
  validate_cmd->add_option("files", scenario_files,
                           "Scenario files (.json); none: the shipped scenarios");

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
  simulate_cmd->add_option("--integrator", sim.integrator,
                           "central-difference, rk4, dopri5, backward-euler or bdf2 (default: the "
                           "scenario's, else central-difference)");
  simulate_cmd
      ->add_option("--dt", sim.dt_s,
                   "Requested integrator step (s; 0: the stable step, explicit schemes only)")
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

  MaterialTestOptions material;
  auto* material_cmd = app.add_subcommand(
      "material-test",
      "Hold a strain (relaxation) or a stress (creep, yield-creep) on one material point of the "
      "viscous tissue law and compare the curve with the seed's closed form (Eq. 2, 3, 4). The "
      "default parameters are ASSUMED, not measured: the seed's E = 3500 Pa taken as the "
      "instantaneous modulus E1 + E2 and split 2000 + 1500 Pa, eta1 = 2000 Pa s (tau = 1 s), and "
      "for yield-creep a stress of 1 Pa over a yield limit of 0.5 Pa, eta2 = 500 Pa s^n, n = 0.5");
  const std::map<std::string, MaterialTest> material_tests{
      {"relaxation", MaterialTest::relaxation},
      {"creep", MaterialTest::creep},
      {"yield-creep", MaterialTest::yield_creep}};
  std::string material_test_name;
  material_cmd
      ->add_option("test", material_test_name,
                   "relaxation (Eq. 2), creep (Eq. 3) or yield-creep (Eq. 4)")
      ->required()
      ->check(CLI::IsMember(material_tests));
  material_cmd->add_option("--e1", material.e1_pa, "Maxwell-arm spring E1 (Pa; assumed)")
      ->capture_default_str();
  material_cmd
      ->add_option("--e2", material.e2_pa, "Parallel spring E2, the relaxed modulus (Pa; assumed)")
      ->capture_default_str();
  material_cmd->add_option("--eta1", material.eta1_pa_s, "Maxwell-arm dashpot eta1 (Pa s; assumed)")
      ->capture_default_str();
  material_cmd->add_option("--poisson", material.poisson_ratio, "Poisson's ratio")
      ->capture_default_str();
  auto* yield_option =
      material_cmd
          ->add_option("--yield", material.yield_limit_pa, "Yield limit (Pa; yield-creep; assumed)")
          ->capture_default_str();
  auto* eta2_option = material_cmd
                          ->add_option("--eta2", material.eta2_pa_s_pow_n,
                                       "Viscoplastic viscosity eta2 (Pa s^n; yield-creep; assumed)")
                          ->capture_default_str();
  auto* n_option = material_cmd
                       ->add_option("--n", material.creep_index_n,
                                    "Creep index n in (0, 1] (yield-creep; assumed)")
                       ->capture_default_str();
  auto* strain_option =
      material_cmd->add_option("--strain", material.strain, "Held axial strain (relaxation)")
          ->capture_default_str();
  auto* stress_option = material_cmd
                            ->add_option("--stress", material.stress_pa,
                                         "Held nominal axial stress (Pa; creep, yield-creep)")
                            ->capture_default_str();
  material_cmd->add_option("--duration", material.duration_s, "Simulated time (s)")
      ->capture_default_str();
  material_cmd->add_option("--dt", material.dt_s, "Time step (s)")->capture_default_str();
  material_cmd->add_option("--csv", material.csv_output,
                           "Write time_s, simulated, analytic, relative_error as CSV");
  material_cmd->add_option("--plot", material.plot_output,
                           "Write a PNG plot of both curves (needs X or xvfb-run)");
  material_cmd->add_option("--table", material.table_output,
                           "Also append the largest error as a row of this markdown table (its "
                           "header first when the file is new; docs/material-verification.md)");

  const auto run_experiment = add_experiment_command(app);
  const auto run_study = add_study_command(app);
  const auto run_bench = add_bench_command(app);
  const auto run_cut_bench = add_cut_bench_command(app);
  const auto run_servo_bench = add_servo_bench_command(app);
  const auto run_render_bench = add_render_bench_command(app);
  const auto run_sessions = add_sessions_command(app);
  const auto run_record = add_record_command(app);
  const auto run_server = add_server_command(app);

  try {
    app.parse(argc, argv);
    if (force.size() == 3) sim.force_n = {force[0], force[1], force[2]};
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  if (auto exit_code = run_experiment()) return *exit_code;
  if (auto exit_code = run_study()) return *exit_code;
  if (auto exit_code = run_bench()) return *exit_code;
  if (auto exit_code = run_cut_bench()) return *exit_code;
  if (auto exit_code = run_servo_bench()) return *exit_code;
  if (auto exit_code = run_render_bench()) return *exit_code;
  if (auto exit_code = run_sessions()) return *exit_code;
  if (auto exit_code = run_record()) return *exit_code;
  if (auto exit_code = run_server()) return *exit_code;
  if (report->parsed()) return mesh_report(report_options);
  if (simulate_cmd->parsed()) return simulate(sim);
  if (validate_cmd->parsed()) return validate_scenarios(scenario_files);
  if (screenshot_cmd->parsed()) return screenshot(shot);
  if (material_cmd->parsed()) {
    material.test = material_tests.at(material_test_name);
    // An option of another test would be silently ignored: say so instead.
    const bool yield_creep = material.test == MaterialTest::yield_creep;
    for (const CLI::Option* option : {yield_option, eta2_option, n_option})
      if (option->count() > 0 && !yield_creep)
        return fail(option->get_name() + " applies to yield-creep only");
    if (strain_option->count() > 0 && material.test != MaterialTest::relaxation)
      return fail("--strain applies to relaxation only (creep holds --stress)");
    if (stress_option->count() > 0 && material.test == MaterialTest::relaxation)
      return fail("--stress applies to creep and yield-creep only (relaxation holds --strain)");
    return material_test(material);
  }
  if (demo_cmd->parsed()) return demo(demo_shot);
  return 1;
}
