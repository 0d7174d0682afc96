#include "experiment_commands.h"

#include "cli_commands.h"

#include "liversim/engine/integrator.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/studies/seed_experiments.h"

#include <CLI/CLI.hpp>

#ifdef LIVERSIM_HAVE_RENDER
#include "render/curve_plot.h"
#endif

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace liversim::cli {
namespace {

// One line on what the integrator did, in the words of StepReport.
std::string step_summary(const SimModel& model, const StepReport& steps) {
  std::ostringstream text;
  text << std::setprecision(4) << integrator_name(model.integrator.kind) << ", requested step ";
  if (model.integrator.step_s > 0.0)
    text << model.integrator.step_s * 1e3 << " ms";
  else
    text << "the stable one";
  if (is_explicit(model.integrator.kind))
    text << " (stable explicit step at rest " << model.stable_time_step_s * 1e3 << " ms)";
  text << ": " << steps.substeps << " steps of " << steps.smallest_substep_s * 1e3 << " to "
       << steps.largest_substep_s * 1e3 << " ms, " << steps.force_evaluations
       << " force evaluations";
  if (steps.stability_limited_steps > 0)
    text << "; " << steps.stability_limited_steps
         << " steps shortened by the stability limit (smallest stable step "
         << steps.smallest_stable_step_s * 1e3 << " ms)";
  if (steps.rejected_steps > 0) text << "; " << steps.rejected_steps << " rejected steps";
  if (steps.newton_iterations > 0)
    text << "; " << steps.newton_iterations << " Newton iterations, " << steps.factorizations
         << " factorisations, " << steps.unconverged_steps << " unconverged steps";
  return text.str();
}

std::ofstream open_csv(const std::filesystem::path& file) {
  std::ofstream csv(file);
  if (!csv) throw std::runtime_error("cannot write " + file.string());
  csv << std::setprecision(10);
  return csv;
}

void close_csv(std::ofstream& csv, const std::filesystem::path& file) {
  csv.close();
  if (!csv) throw std::runtime_error("writing " + file.string() + " failed");
  std::cout << "wrote " << file.string() << "\n";
}

struct PlotSeries {
  std::string name;
  std::vector<double> y;
  bool dashed = false;
};

void write_plot(const std::filesystem::path& file, const std::string& title,
                const std::string& x_label, const std::string& y_label,
                const std::vector<double>& x, const std::vector<PlotSeries>& series) {
#ifdef LIVERSIM_HAVE_RENDER
  std::vector<CurveSeries> curves;
  for (const PlotSeries& s : series) curves.push_back({s.name, s.y, s.dashed});
  write_curve_plot_png(file, title, x_label, y_label, x, curves, 800, 500);
  std::cout << "wrote " << file.string() << "\n";
#else
  (void)title, (void)x_label, (void)y_label, (void)x, (void)series;
  throw std::runtime_error("cannot write " + file.string() +
                           ": this liversim-cli was built without the renderer "
                           "(LIVERSIM_BUILD_UI=OFF)");
#endif
}

// Writes a table the command printed to --table FILE (docs/seed-experiments.md takes it from
// there).
void write_table(const std::optional<std::filesystem::path>& file, const std::string& table) {
  if (!file) return;
  std::ofstream out(*file);
  out << table;
  out.close();
  if (!out) throw std::runtime_error("cannot write " + file->string());
  std::cout << "wrote " << file->string() << "\n";
}

void require_positive(double value, const std::string& option, const char* unit) {
  if (!std::isfinite(value) || value <= 0.0)
    throw std::invalid_argument(option + " " + number(value) + unit +
                                " is invalid: expected a finite value > 0");
}

}  // namespace

int creep_experiment(const CreepExperimentOptions& o) {
  return guarded([&]() -> int {
    const IntegratorSettings integrator = integrator_settings(o.model.integrator, o.model.dt_s);
    require_positive(o.peak_force_n, "--force", " N");
    require_positive(o.ramp_time_s, "--ramp-time", " s");
    require_positive(o.sample_interval_s, "--sample-interval", " s");
    if (!std::isfinite(o.duration_s) || o.duration_s < o.sample_interval_s)
      throw std::invalid_argument("--duration " + number(o.duration_s) +
                                  " s is invalid: expected at least --sample-interval (" +
                                  number(o.sample_interval_s) + " s)");
    if (integrator.step_s > o.sample_interval_s)
      throw std::invalid_argument("--dt " + number(integrator.step_s) +
                                  " s exceeds --sample-interval " + number(o.sample_interval_s) +
                                  " s (the load changes every sample)");

    const ExperimentScene built = build_scene(o.model.tet_count, integrator, o.viscoelastic);
    CreepSettings settings;
    settings.peak_force_n = o.peak_force_n;
    settings.ramp_time_s = o.ramp_time_s;
    settings.duration_s = o.duration_s;
    settings.sample_interval_s = o.sample_interval_s;
    settings.load_radius_m = o.load_radius_m;
    const CreepResult result = run_creep_experiment(built.scene.mesh, built.model, settings);

    // The samples at the end of the ramp and at the end.
    std::size_t ramp_end = 0;
    while (ramp_end + 1 < result.time_s.size() &&
           result.time_s[ramp_end + 1] <= o.ramp_time_s * (1.0 + 1e-12))
      ++ramp_end;
    const std::size_t last = result.time_s.size() - 1;
    std::cout << std::setprecision(5) << "experiment creep: " << built.scene.description
              << (o.viscoelastic ? ", viscoelastic (assumed E1 = 2000 Pa, E2 = 1500 Pa, eta1 = "
                                   "2000 Pa s)"
                                 : ", elastic")
              << "; tension rising linearly to " << o.peak_force_n << " N over " << o.ramp_time_s
              << " s, then held, along +z (anterior), on node " << result.patch.marked_node
              << " spread over " << result.patch.nodes.size() << " surface nodes within "
              << o.load_radius_m * 1e3 << " mm\n"
              << step_summary(built.model, result.steps) << "; " << result.wall_time_s
              << " s wall time\n"
              << "displacement of the marked point at the end of the ramp (t = "
              << result.time_s[ramp_end] << " s): " << result.displacement_mm[ramp_end]
              << " mm; at t = " << result.time_s[last] << " s: " << result.displacement_mm[last]
              << " mm (creep while held "
              << result.displacement_mm[last] - result.displacement_mm[ramp_end] << " mm)\n";
    if (!result.secant_ratio_mm_per_n.empty())
      std::cout << "displacement / force at the peak force: " << result.secant_ratio_mm_per_n.back()
                << " mm/N; displacement change / force change over the last ramp interval: "
                << result.incremental_ratio_mm_per_n.back() << " mm/N\n";

    if (o.table_output) {
      // Every quarter of the ramp, to the end; the ratios over the ramp only.
      std::ostringstream table;
      table << "| t (s) | force (N) | \\|u\\| (mm) | u along the load (mm) | \\|u\\| / force "
               "(mm/N) | change of \\|u\\| / change of force over the last "
            << number(o.sample_interval_s * 1e3) << " ms (mm/N) |\n"
            << "|---:|---:|---:|---:|---:|---:|\n";
      const double every_s = o.ramp_time_s / 4.0;
      for (std::size_t i = 0; i < result.time_s.size(); ++i) {
        const double t = result.time_s[i];
        const double quarters = t / every_s;
        if (std::abs(quarters - std::round(quarters)) > 1e-6 * std::max(1.0, quarters)) continue;
        const bool on_ramp = i >= 1 && i <= result.incremental_ratio_mm_per_n.size();
        table << std::fixed << std::setprecision(2) << "| " << t << " | " << result.force_n[i]
              << " | " << result.displacement_mm[i] << " | " << result.displacement_along_load_mm[i]
              << " | ";
        if (on_ramp)
          table << std::setprecision(1) << result.secant_ratio_mm_per_n[i - 1] << " | "
                << result.incremental_ratio_mm_per_n[i - 1] << " |\n";
        else
          table << "– | – |\n";
      }
      table << std::defaultfloat << "\n"
            << step_summary(built.model, result.steps) << "; " << format(result.wall_time_s)
            << " s wall time.\n";
      write_table(o.table_output, table.str());
    }
    if (o.csv_output) {
      std::ofstream csv = open_csv(*o.csv_output);
      csv << "time_s,force_n,displacement_mm,displacement_along_load_mm\n";
      for (std::size_t i = 0; i < result.time_s.size(); ++i)
        csv << result.time_s[i] << "," << result.force_n[i] << "," << result.displacement_mm[i]
            << "," << result.displacement_along_load_mm[i] << "\n";
      close_csv(csv, *o.csv_output);
    }
    if (o.ratio_csv_output) {
      std::ofstream csv = open_csv(*o.ratio_csv_output);
      csv << "force_n,incremental_ratio_mm_per_n,secant_ratio_mm_per_n\n";
      for (std::size_t i = 0; i < result.ratio_force_n.size(); ++i)
        csv << result.ratio_force_n[i] << "," << result.incremental_ratio_mm_per_n[i] << ","
            << result.secant_ratio_mm_per_n[i] << "\n";
      close_csv(csv, *o.ratio_csv_output);
    }
    if (o.plot_output)
      write_plot(*o.plot_output,
                 "Creep of the marked point: " + number(o.peak_force_n) + " N reached at " +
                     number(o.ramp_time_s) + " s, then held",
                 "time (s)", "displacement (mm)", result.time_s,
                 {{"|u| of the marked point", result.displacement_mm, false},
                  {"u along the load", result.displacement_along_load_mm, true}});
    if (o.ratio_plot_output)
      write_plot(*o.ratio_plot_output, "Displacement per force during the ramp",
                 "applied force (N)", "ratio (mm/N)", result.ratio_force_n,
                 {{"displacement change / force change", result.incremental_ratio_mm_per_n, false},
                  {"displacement / force", result.secant_ratio_mm_per_n, true}});
    return 0;
  });
}

int pull_experiment(const PullExperimentOptions& o) {
  return guarded([&]() -> int {
    const IntegratorSettings integrator = integrator_settings(o.model.integrator, o.model.dt_s);
    if (o.forces_n.empty()) throw std::invalid_argument("--forces needs at least one force");
    for (double f : o.forces_n) require_positive(f, "--forces", " N");
    require_positive(o.residual_tolerance, "--tolerance", "");
    require_positive(o.max_time_s, "--max-time", " s");
    PullSettings settings;
    if (integrator.step_s > settings.check_interval_s)
      throw std::invalid_argument("--dt " + number(integrator.step_s) +
                                  " s exceeds the check interval " +
                                  number(settings.check_interval_s) + " s");

    const ExperimentScene built = build_scene(o.model.tet_count, integrator);
    settings.forces_n = o.forces_n;
    settings.load_radius_m = o.load_radius_m;
    settings.residual_tolerance = o.residual_tolerance;
    settings.max_time_s = o.max_time_s;
    const bool forceps = o.attachment == "forceps";
    settings.attachment = forceps ? PullAttachment::forceps : PullAttachment::load_patch;
    const PullResult result = run_pull_experiment(built.scene.mesh, built.model, settings);

    std::cout << std::setprecision(5) << "experiment pull: " << built.scene.description
              << (forceps ? "; the forceps closed on node " : "; forceps load along +z on node ")
              << result.patch.marked_node
              << (forceps ? ", holding the surface nodes within "
                          : ", spread over the surface "
                            "nodes within ")
              << o.load_radius_m * 1e3
              << " mm, pulled along +z (anterior) with a force rising over " << settings.ramp_time_s
              << " s, then held\n"
              << "settled: sum over free nodes of |internal + load| <= " << o.residual_tolerance
              << " x applied force at every check (every " << settings.check_interval_s
              << " s) for " << settings.settle_window_s
              << " s; this bounds |feedback - applied| / applied by " << o.residual_tolerance
              << "\n\n";
    std::ostringstream table;
    table << "| applied (N) | held nodes | feedback along load (N) | relative error | bound R/F | "
             "settled at (s) | displacement (mm) | steps | wall (s) |\n"
          << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    bool all_settled = true;
    for (const PullCase& c : result.cases) {
      all_settled = all_settled && c.settled;
      table << std::defaultfloat << std::setprecision(6) << "| " << c.applied_force_n << " | "
            << c.held_nodes << " | " << std::fixed << std::setprecision(6)
            << c.feedback_n.dot(settings.direction) << " | " << std::scientific
            << std::setprecision(2) << c.relative_error << " | " << c.bound_relative_error << " | "
            << std::fixed << std::setprecision(2) << c.settle_time_s
            << (c.settled ? "" : " (not settled)") << " | " << c.displacement_mm << " | "
            << c.steps.substeps << " | " << c.wall_time_s << " |\n";
    }
    std::cout << table.str() << std::defaultfloat << std::setprecision(5) << "\n";
    write_table(o.table_output, table.str());
    for (const PullCase& c : result.cases)
      std::cout << c.applied_force_n << " N: " << step_summary(built.model, c.steps) << "\n";

    if (o.csv_output) {
      std::ofstream csv = open_csv(*o.csv_output);
      csv << "applied_force_n,feedback_x_n,feedback_y_n,feedback_z_n,feedback_along_load_n,"
             "relative_error,residual_l1_n,error_bound,settled,settle_time_s,displacement_mm,"
             "steps,wall_time_s\n";
      for (const PullCase& c : result.cases)
        csv << c.applied_force_n << "," << c.feedback_n.x() << "," << c.feedback_n.y() << ","
            << c.feedback_n.z() << "," << c.feedback_n.dot(settings.direction) << ","
            << c.relative_error << "," << c.residual_l1_n << "," << c.bound_relative_error << ","
            << (c.settled ? 1 : 0) << "," << c.settle_time_s << "," << c.displacement_mm << ","
            << c.steps.substeps << "," << c.wall_time_s << "\n";
      close_csv(csv, *o.csv_output);
    }
    if (o.history_csv_output) {
      std::ofstream csv = open_csv(*o.history_csv_output);
      csv << "applied_force_n,time_s,feedback_along_load_n\n";
      for (const PullCase& c : result.cases)
        for (std::size_t i = 0; i < c.history_time_s.size(); ++i)
          csv << c.applied_force_n << "," << c.history_time_s[i] << ","
              << c.history_feedback_along_load_n[i] << "\n";
      close_csv(csv, *o.history_csv_output);
    }
    if (o.plot_output) {
      // Feedback over applied force against time, over the span every case reached.
      std::size_t samples = result.cases.front().history_time_s.size();
      for (const PullCase& c : result.cases) samples = std::min(samples, c.history_time_s.size());
      const std::vector<double> time_s(result.cases.front().history_time_s.begin(),
                                       result.cases.front().history_time_s.begin() + samples);
      std::vector<PlotSeries> series;
      for (const PullCase& c : result.cases) {
        PlotSeries s{number(c.applied_force_n) + " N", {}, false};
        for (std::size_t i = 0; i < samples; ++i)
          s.y.push_back(c.history_feedback_along_load_n[i] / c.applied_force_n);
        series.push_back(std::move(s));
      }
      series.push_back({"applied (after the ramp)", std::vector<double>(samples, 1.0), true});
      write_plot(*o.plot_output, "Forceps pull: feedback force / applied force", "time (s)",
                 "feedback / applied", time_s, series);
    }
    if (!all_settled)
      return fail("a pull did not settle within --max-time " + number(o.max_time_s) +
                  " s; its figures are not equilibrium figures");
    return 0;
  });
}

int timing_experiment(const TimingExperimentOptions& o) {
  return guarded([&]() -> int {
    require_positive(o.dt_s, "--dt", " s");
    const IntegratorSettings integrator = integrator_settings(o.integrator, o.dt_s);
    require_positive(o.force_n, "--force", " N");
    require_positive(o.simulated_s, "--time", " s");
    if (o.simulated_s < o.dt_s)
      throw std::invalid_argument("--time " + number(o.simulated_s) + " s is shorter than --dt " +
                                  number(o.dt_s) + " s");
    if (o.tet_counts.empty())
      throw std::invalid_argument("--tets needs at least one element count");

    TimingSettings settings;
    settings.force_n = o.force_n;
    settings.frame_s = o.dt_s;
    settings.simulated_s = o.simulated_s;
    struct Row {
      int requested_tets;
      const SeedTable1Row* seed;
      double build_wall_s;
      TimingCase timing;
    };
    std::vector<Row> rows;
    std::string integrator_line;
    for (int tets : o.tet_counts) {
      const ExperimentScene built = build_scene(tets, integrator);
      const SeedTable1Row* seed = nullptr;
      for (const SeedTable1Row& row : kSeedTable1)
        if (row.tets == tets) seed = &row;
      rows.push_back({tets, seed, built.build_wall_s,
                      run_timing_case(built.scene.mesh, built.model, settings)});
      std::cout << std::setprecision(5) << tets
                << " tets: " << step_summary(built.model, rows.back().timing.steps) << "\n";
    }

    std::cout << "\nexperiment timing: built-in liver, " << o.force_n
              << " N along +z (anterior) on the marked point, from rest; "
              << rows.front().timing.frames << " frames of " << o.dt_s * 1e3 << " ms ("
              << o.simulated_s << " s simulated), integrator " << o.integrator
              << ". Deformation time = wall time of the frames' advance() calls (model build "
                 "excluded); one thread.\n\n";
    std::ostringstream table;
    table << "| tets (seed) | tets (ours) | nodes | deformation time (ms per " << o.simulated_s
          << " s) | per frame (ms) | steps | force evaluations | per step (µs) | steps/s | "
             "real-time factor | stability-limited steps | smallest stable step (ms) | u (mm) | "
             "seed deform | [3] deform | [14] deform |\n"
          << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const Row& row : rows) {
      const TimingCase& t = row.timing;
      table << std::fixed << "| " << row.requested_tets << " | " << t.tet_count << " | "
            << t.node_count << " | " << std::setprecision(1) << t.deformation_wall_s * 1e3 << " | "
            << std::setprecision(3) << t.wall_per_frame_s() * 1e3 << " | " << t.steps.substeps
            << " | " << t.steps.force_evaluations << " | " << std::setprecision(1)
            << t.wall_per_substep_s() * 1e6 << " | " << std::setprecision(0)
            << t.substeps_per_wall_s() << " | " << std::setprecision(2)
            << t.real_time_factor(settings) << " | " << t.steps.stability_limited_steps << " | "
            << (t.steps.stability_limited_steps > 0 ? number(t.steps.smallest_stable_step_s * 1e3)
                                                    : std::string("-"))
            << " | " << std::setprecision(2) << t.displacement_mm << " | ";
      if (row.seed)
        table << std::setprecision(1) << row.seed->seed_deform_ms << " | "
              << row.seed->conical_spring_deform_ms << " | " << row.seed->implicit_fem_deform_ms
              << " |\n";
      else
        table << "- | - | - |\n";
    }
    std::cout << table.str() << std::defaultfloat
              << "\nSeed columns: Table 1 of the seed (unit not stated, read as ms; its "
                 "\"deformation time\" is not defined; i7-10700). [3] conical-spring model, [14] "
                 "FEM with optimised implicit Euler. Cutting times: liversim-cli bench-cut "
                 "(docs/cutting-performance.md).\n";
    write_table(o.table_output, table.str());

    if (o.csv_output) {
      std::ofstream csv = open_csv(*o.csv_output);
      csv << "requested_tets,tets,nodes,integrator,frame_s,frames,simulated_s,deformation_wall_ms,"
             "wall_per_frame_ms,steps,wall_per_step_us,steps_per_s,real_time_factor,"
             "stability_limited_steps,smallest_stable_step_ms,stable_step_at_rest_ms,"
             "force_evaluations,newton_iterations,displacement_mm,model_build_s,seed_deform_ms,"
             "conical_spring_deform_ms,implicit_fem_deform_ms\n";
      for (const Row& row : rows) {
        const TimingCase& t = row.timing;
        csv << row.requested_tets << "," << t.tet_count << "," << t.node_count << ","
            << o.integrator << "," << o.dt_s << "," << t.frames << "," << o.simulated_s << ","
            << t.deformation_wall_s * 1e3 << "," << t.wall_per_frame_s() * 1e3 << ","
            << t.steps.substeps << "," << t.wall_per_substep_s() * 1e6 << ","
            << t.substeps_per_wall_s() << "," << t.real_time_factor(settings) << ","
            << t.steps.stability_limited_steps << "," << t.steps.smallest_stable_step_s * 1e3 << ","
            << t.stable_step_at_rest_s * 1e3 << "," << t.steps.force_evaluations << ","
            << t.steps.newton_iterations << "," << t.displacement_mm << "," << row.build_wall_s
            << ",";
        if (row.seed)
          csv << row.seed->seed_deform_ms << "," << row.seed->conical_spring_deform_ms << ","
              << row.seed->implicit_fem_deform_ms << "\n";
        else
          csv << ",,\n";
      }
      close_csv(csv, *o.csv_output);
    }
    if (o.plot_output) {
      std::vector<double> tets;
      PlotSeries ours{"ours (" + o.integrator + ")", {}, false};
      PlotSeries seed{"seed", {}, true}, spring{"[3] conical spring", {}, true},
          implicit{"[14] implicit FEM", {}, true};
      const bool all_seed_sizes =
          std::all_of(rows.begin(), rows.end(), [](const Row& row) { return row.seed; });
      for (const Row& row : rows) {
        tets.push_back(row.requested_tets);
        ours.y.push_back(row.timing.deformation_wall_s * 1e3);
        if (all_seed_sizes) {
          seed.y.push_back(row.seed->seed_deform_ms);
          spring.y.push_back(row.seed->conical_spring_deform_ms);
          implicit.y.push_back(row.seed->implicit_fem_deform_ms);
        }
      }
      std::vector<PlotSeries> series{ours};
      if (all_seed_sizes) series.insert(series.end(), {seed, spring, implicit});
      write_plot(*o.plot_output,
                 "Deformation time: wall time for " + number(o.simulated_s) +
                     " s at dt = " + number(o.dt_s) + " s, " + number(o.force_n) + " N",
                 "tetrahedra", "deformation time (ms)", tets, series);
    }
    return 0;
  });
}

namespace {

void add_model_options(CLI::App& command, ExperimentModelOptions& model) {
  command.add_option("--tets", model.tet_count, "Element count of the built-in liver")
      ->check(CLI::Range(100, 2'000'000))
      ->capture_default_str();
  command
      .add_option("--integrator", model.integrator,
                  "central-difference, rk4, dopri5, backward-euler or bdf2")
      ->capture_default_str();
  command
      .add_option("--dt", model.dt_s,
                  "Integrator step (s); 0: the largest stable step (explicit schemes)")
      ->capture_default_str();
}

}  // namespace

std::function<std::optional<int>()> add_experiment_command(CLI::App& app) {
  struct Options {
    CreepExperimentOptions creep;
    PullExperimentOptions pull;
    TimingExperimentOptions timing;
  };
  auto options = std::make_shared<Options>();
  auto* experiment = app.add_subcommand(
      "experiment",
      "The seed's experiments on the built-in liver: creep (seed 4.2), pull (4.3), timing (4.4)");
  experiment->require_subcommand(1);

  CreepExperimentOptions& creep = options->creep;
  auto* creep_cmd = experiment->add_subcommand(
      "creep",
      "A tension rising linearly to --force over --ramp-time, then held, on the marked anterior "
      "point: its displacement over time and displacement / force");
  add_model_options(*creep_cmd, creep.model);
  creep_cmd->add_option("--force", creep.peak_force_n, "Peak tension (N)")->capture_default_str();
  creep_cmd->add_option("--ramp-time", creep.ramp_time_s, "Time of the linear rise (s)")
      ->capture_default_str();
  creep_cmd->add_option("--duration", creep.duration_s, "Simulated time (s)")
      ->capture_default_str();
  creep_cmd->add_option("--sample-interval", creep.sample_interval_s, "Sample interval (s)")
      ->capture_default_str();
  creep_cmd
      ->add_option("--load-radius", creep.load_radius_m,
                   "Spread the load over surface nodes within this radius (m)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  creep_cmd->add_flag("--viscoelastic", creep.viscoelastic,
                      "Tissue with material-test's assumed SLS (E1 2000 Pa, E2 1500 Pa, eta1 "
                      "2000 Pa s) instead of the elastic one");
  creep_cmd->add_option("--csv", creep.csv_output,
                        "Write time_s, force_n, displacement_mm, displacement_along_load_mm");
  creep_cmd->add_option("--ratio-csv", creep.ratio_csv_output,
                        "Write force_n and the displacement / force ratios over the ramp");
  creep_cmd->add_option("--plot", creep.plot_output,
                        "PNG of displacement vs time (needs X or xvfb-run)");
  creep_cmd->add_option("--ratio-plot", creep.ratio_plot_output,
                        "PNG of displacement / force vs force (needs X or xvfb-run)");
  creep_cmd->add_option("--table", creep.table_output,
                        "Write the marked point's displacement every quarter of the ramp as a "
                        "markdown table");

  PullExperimentOptions& pull = options->pull;
  auto* pull_cmd = experiment->add_subcommand(
      "pull",
      "Forceps pulls with each force from rest to equilibrium: the feedback force (elastic "
      "reaction of the grabbed nodes) against the applied one");
  add_model_options(*pull_cmd, pull.model);
  pull_cmd->add_option("--forces", pull.forces_n, "Applied forces (N)")->capture_default_str();
  pull_cmd
      ->add_option("--load-radius", pull.load_radius_m, "Radius of the grabbed surface patch (m)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  pull_cmd
      ->add_option("--tolerance", pull.residual_tolerance,
                   "Settled when the summed |net nodal force| is below this times the force")
      ->capture_default_str();
  pull_cmd->add_option("--max-time", pull.max_time_s, "Give up after this simulated time (s)")
      ->capture_default_str();
  pull_cmd
      ->add_option("--attachment", pull.attachment,
                   "How the pull reaches the tissue: patch (point loads over the patch) or forceps "
                   "(the forceps close on the marked point and a hand pulls them with the force)")
      ->check(CLI::IsMember({"patch", "forceps"}))
      ->capture_default_str();
  pull_cmd->add_option("--csv", pull.csv_output, "Write one row per force");
  pull_cmd->add_option("--history-csv", pull.history_csv_output,
                       "Write the feedback force at every check");
  pull_cmd->add_option("--plot", pull.plot_output,
                       "PNG of feedback / applied force vs time (needs X or xvfb-run)");
  pull_cmd->add_option("--table", pull.table_output, "Write the table printed as a markdown file");

  TimingExperimentOptions& timing = options->timing;
  auto* timing_cmd = experiment->add_subcommand(
      "timing",
      "The seed's Table 1: wall time to simulate the loaded liver at the seed's mesh sizes");
  timing_cmd->add_option("--tets", timing.tet_counts, "Element counts of the built-in liver")
      ->delimiter(',')
      ->check(CLI::Range(100, 2'000'000))
      ->capture_default_str();
  timing_cmd
      ->add_option("--integrator", timing.integrator,
                   "central-difference, rk4, dopri5, backward-euler or bdf2")
      ->capture_default_str();
  timing_cmd
      ->add_option("--dt", timing.dt_s, "Frame and requested integrator step (s; the seed's 0.002)")
      ->capture_default_str();
  timing_cmd->add_option("--force", timing.force_n, "Load (N)")->capture_default_str();
  timing_cmd->add_option("--time", timing.simulated_s, "Simulated time per size (s)")
      ->capture_default_str();
  timing_cmd->add_option("--csv", timing.csv_output, "Write one row per size");
  timing_cmd->add_option("--plot", timing.plot_output,
                         "PNG of deformation time vs size beside the seed's (needs X)");
  timing_cmd->add_option("--table", timing.table_output,
                         "Write the table printed as a markdown file");

  return [=]() -> std::optional<int> {
    if (creep_cmd->parsed()) return creep_experiment(options->creep);
    if (pull_cmd->parsed()) return pull_experiment(options->pull);
    if (timing_cmd->parsed()) return timing_experiment(options->timing);
    return std::nullopt;
  };
}

}  // namespace liversim::cli
