#include "study_command.h"

#include "cli_commands.h"
#include "stability_command.h"

#include "liversim/studies/accuracy_study.h"

#ifdef LIVERSIM_HAVE_RENDER
#include "render/curve_plot.h"
#endif

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

namespace liversim::cli {
namespace {

struct StudyCommandOptions {
  AccuracyStudyOptions study;
  std::vector<std::string> integrators{"central-difference", "rk4", "dopri5", "backward-euler",
                                       "bdf2"};
  std::vector<std::string> effects{"elastic"};
  std::vector<double> steps_ms{1.0, 0.5, 0.25};
  std::filesystem::path output_dir = "docs";
  bool plots = true;
  std::string command_line;
};

// A bar on stderr, redrawn in place on a terminal, one line per run otherwise (logs, CI).
bool print_progress(const StudyProgressReport& report) {
  static const bool terminal = isatty(fileno(stderr)) != 0;
  constexpr int kWidth = 30;
  const int done = report.runs_done, total = report.runs_total;
  if (terminal) {
    const double runs = done + report.fraction_of_run;
    const int filled = total > 0 ? static_cast<int>(runs * kWidth / total) : kWidth;
    std::cerr << "\r[" << std::string(static_cast<std::size_t>(filled), '#')
              << std::string(static_cast<std::size_t>(kWidth - filled), '.') << "] " << done << "/"
              << total << "  " << report.running.substr(0, 70) << "\x1b[K" << std::flush;
    if (done == total) std::cerr << "\n";
  } else if (report.fraction_of_run == 0.0) {
    std::cerr << "[" << done << "/" << total << "] " << report.running << "\n";
  }
  return true;
}

std::string setting_of(const AccuracyStudyRow& row) {
  return row.integrator == IntegratorKind::dopri5 ? "tol " + format(row.tolerance_m) + " m"
                                                  : "Δt " + format(row.step_s * 1e3) + " ms";
}

std::string group_key(const AccuracyStudyRow& row) {
  return std::to_string(row.tet_count) + "-" + std::string(study_effects_name(row.effects));
}

void write_mesh_csv(const std::filesystem::path& file, const AccuracyStudyResult& result) {
  std::ofstream csv(file);
  csv << "tets,effects,ux_m,uy_m,uz_m,difference_from_finest_m,reference_wall_s\n"
      << std::setprecision(8);
  for (const MeshConvergenceRow& row : result.mesh_rows)
    csv << row.tet_count << ',' << study_effects_name(row.effects) << ',' << row.displacement_m.x()
        << ',' << row.displacement_m.y() << ',' << row.displacement_m.z() << ','
        << row.difference_from_finest_m << ',' << row.reference_wall_s << '\n';
  if (!csv) throw std::runtime_error("cannot write " + file.string());
}

#ifdef LIVERSIM_HAVE_RENDER
// Per integrator, its runs in order of the setting (coarse to fine).
std::vector<ScatterSeries> series_by_integrator(const std::vector<const AccuracyStudyRow*>& group,
                                                const AccuracyStudyOptions& options,
                                                bool against_cost) {
  std::vector<ScatterSeries> series;
  for (IntegratorKind kind : kAllIntegrators) {
    ScatterSeries s;
    s.name = std::string(integrator_name(kind));
    for (const AccuracyStudyRow* row : group) {
      if (row->integrator != kind) continue;
      if (!against_cost && kind == IntegratorKind::dopri5) {
        s.x.push_back(row->mean_step_s(options) * 1e3);  // its average step
      } else {
        s.x.push_back(against_cost ? row->wall_per_simulated_s(options)
                                   : row->mean_step_s(options) * 1e3);
      }
      s.y.push_back(row->max_node_error_m * 1e3);
    }
    if (!s.x.empty()) series.push_back(std::move(s));
  }
  return series;
}
#endif

double load_interval_ms(const AccuracyStudyOptions& options) {
  return options.steps_s.empty()
             ? 1.0
             : *std::max_element(options.steps_s.begin(), options.steps_s.end()) * 1e3;
}

int run_study(const StudyCommandOptions& command) {
  AccuracyStudyOptions options = command.study;
  options.integrators.clear();
  for (const std::string& name : command.integrators)
    options.integrators.push_back(integrator_kind(name));
  options.effects.clear();
  for (const std::string& name : command.effects) {
    const auto effects = study_effects_from_name(name);
    if (!effects) {
      std::string valid;
      for (StudyEffects e : kAllStudyEffects) valid += " " + std::string(study_effects_name(e));
      return fail("unknown effect set '" + name + "': expected one of" + valid);
    }
    options.effects.push_back(*effects);
  }
  options.steps_s.clear();
  for (double ms : command.steps_ms) options.steps_s.push_back(ms * 1e-3);

  std::error_code error;
  std::filesystem::create_directories(command.output_dir / "images", error);
  if (error)
    return fail("cannot create " + (command.output_dir / "images").string() + ": " +
                error.message());

  const AccuracyStudyResult result = run_accuracy_study(options, print_progress);

  const std::filesystem::path csv = command.output_dir / "accuracy-study.csv";
  const std::filesystem::path mesh_csv = command.output_dir / "accuracy-study-meshes.csv";
  {
    std::ofstream csv_file(csv);
    write_accuracy_study_csv(csv_file, options, result);
    if (!csv_file) throw std::runtime_error("cannot write " + csv.string());
  }
  write_mesh_csv(mesh_csv, result);
  std::cout << "wrote " << csv.string() << "\nwrote " << mesh_csv.string() << "\n";

  // Groups of one mesh and effect set, in the order they ran.
  std::vector<std::string> keys;
  std::map<std::string, std::vector<const AccuracyStudyRow*>> groups;
  for (const AccuracyStudyRow& row : result.rows) {
    if (!groups.count(group_key(row))) keys.push_back(group_key(row));
    groups[group_key(row)].push_back(&row);
  }

  std::ostringstream md;
  md << "# Accuracy study: what accuracy costs in time\n\n"
     << written_by(command.command_line)
     << "\n\nEvery run on one thread. Every figure below is from that run; "
        "run the command again to regenerate this page, its CSV and its images.\n\n"
     << "## What is measured\n"
     << "- The experiment: the built-in liver (ligament fixed, E = 3500 Pa, ν = 0.49, average "
        "nodal pressure), a vertical tension at the marked anterior point spread over the surface "
        "nodes within "
     << format(options.load_radius_m * 1e3) << " mm, rising smoothly (x²(3 − 2x)) from 0 to "
     << format(options.peak_force_n) << " N over " << format(options.duration_s * 1e3)
     << " ms. The load is updated every " << format(load_interval_ms(options))
     << " ms (the largest step), so every scheme sees the same forcing.\n"
     << "- Error: distance from a reference run of the same mesh (RK4 at the smallest step / "
     << options.reference_refinement
     << ") at the end, largest over all nodes (`max node error`) and at the marked point.\n"
     << "- Cost: wall time of the `advance()` calls per simulated second (one thread of this "
        "machine), force evaluations of the whole mesh, sparse factorisations and linear solves.\n"
     << "- Explicit schemes never exceed their stability interval: a requested step above it is "
        "split (`limited` counts those steps; `mean step` is the step actually taken).\n"
     << "- Effect sets (parameters ASSUMED, see docs/tissue-model.md): elastic; viscoelastic "
        "(E1 = 2000, E2 = 1500 Pa, τ = 1 s); viscoplastic (+ yield limit 20 Pa, η2 = 500 Pa·sⁿ, "
        "n = 0.5); fibres (HGO k1 = 1000 Pa, k2 = 2, along x).\n\n";

  for (const std::string& key : keys) {
    const auto& group = groups[key];
    const AccuracyStudyRow& first = *group.front();
    md << "## " << first.tet_count << " tetrahedra, " << study_effects_name(first.effects)
       << "\n\n";
#ifdef LIVERSIM_HAVE_RENDER
    if (command.plots) {
      const std::string cost_png = "images/accuracy-cost-" + key + ".png";
      const std::string order_png = "images/accuracy-order-" + key + ".png";
      write_scatter_plot_png(command.output_dir / cost_png,
                             "Error vs cost, " + std::to_string(first.tet_count) + " tets, " +
                                 std::string(study_effects_name(first.effects)),
                             "wall seconds per simulated second", "max node error (mm)",
                             series_by_integrator(group, options, true), true, true, 900, 560);
      write_scatter_plot_png(command.output_dir / order_png,
                             "Error vs step taken, " + std::to_string(first.tet_count) + " tets, " +
                                 std::string(study_effects_name(first.effects)),
                             "mean step (ms)", "max node error (mm)",
                             series_by_integrator(group, options, false), true, true, 900, 560);
      md << "![error vs cost](" << cost_png << ")\n![error vs step](" << order_png << ")\n\n";
      std::cout << "wrote " << (command.output_dir / cost_png).string() << "\nwrote "
                << (command.output_dir / order_png).string() << "\n";
    }
#endif
    const std::vector<bool> front = pareto_front(group);
    md << "| integrator | setting | mean step (ms) | limited | max node error (mm) | marked point "
          "error (mm) | wall s per simulated s | force evals | factorisations | solves | "
          "rejected | estimate (mm) | Pareto |\n"
       << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|:-:|\n";
    for (std::size_t i = 0; i < group.size(); ++i) {
      const AccuracyStudyRow& row = *group[i];
      md << "| " << integrator_name(row.integrator) << " | " << setting_of(row) << " | "
         << format(row.mean_step_s(options) * 1e3) << " | " << row.steps.stability_limited_steps
         << " | " << format(row.max_node_error_m * 1e3) << " | "
         << format(row.marked_point_error_m * 1e3) << " | "
         << format(row.wall_per_simulated_s(options)) << " | " << row.steps.force_evaluations
         << " | " << row.steps.factorizations << " | " << row.steps.linear_solves << " | "
         << row.steps.rejected_steps << " | " << format(row.steps.error_estimate_m * 1e3) << " | "
         << (front[i] ? "●" : "") << " |\n";
    }
    md << "\nObserved orders, log(e₁/e₂)/log(Δt₁/Δt₂) between consecutive settings (tolerances "
          "for dopri5; `–` where a run was stability-limited, so its step was not the one "
          "asked):\n\n| integrator | orders |\n|---|---|\n";
    for (IntegratorKind kind : kAllIntegrators) {
      std::vector<const AccuracyStudyRow*> runs;
      for (const AccuracyStudyRow* row : group)
        if (row->integrator == kind) runs.push_back(row);
      if (runs.size() < 2) continue;
      md << "| " << integrator_name(kind) << " (scheme order " << integrator_order(kind) << ") | ";
      for (std::size_t i = 0; i + 1 < runs.size(); ++i) {
        const double order = observed_order(*runs[i], *runs[i + 1]);
        md << (i ? ", " : "") << setting_of(*runs[i]) << " → " << setting_of(*runs[i + 1]) << ": "
           << (std::isnan(order) ? std::string("–") : format(order, 2));
      }
      md << " |\n";
    }
    md << "\n";
  }

  md << "## Mesh convergence\n\nThe reference run of each mesh against the finest mesh's, at the "
        "same material point (the finest mesh's marked node, interpolated in each mesh):\n\n"
     << "| tets | effects | \\|u\\| (mm) | difference from finest (mm) | reference wall time (s) "
        "|\n|---:|---|---:|---:|---:|\n";
  for (const MeshConvergenceRow& row : result.mesh_rows)
    md << "| " << row.tet_count << " | " << study_effects_name(row.effects) << " | "
       << format(row.displacement_m.norm() * 1e3) << " | "
       << format(row.difference_from_finest_m * 1e3) << " | " << format(row.reference_wall_s)
       << " |\n";
  md << "\nData: [accuracy-study.csv](accuracy-study.csv), "
        "[accuracy-study-meshes.csv](accuracy-study-meshes.csv).\n";

  return write_report(command.output_dir / "accuracy-study.md", md.str());
}

}  // namespace

std::function<std::optional<int>()> add_study_command(CLI::App& app) {
  auto options = std::make_shared<StudyCommandOptions>();
  auto* study = app.add_subcommand(
      "study", "Studies of the engine: accuracy (what it costs), stability (the hard cases)");
  study->require_subcommand(1);
  auto* accuracy = study->add_subcommand(
      "accuracy",
      "Run the loaded liver over integrator x step (or tolerance) x mesh size x effects; write "
      "error and cost as CSV, PNG plots and a markdown report");
  StudyCommandOptions& o = *options;
  accuracy
      ->add_option("--tets", o.study.tet_counts, "Built-in liver sizes (the largest is the finest)")
      ->delimiter(',')
      ->check(CLI::Range(100, 2'000'000))
      ->capture_default_str();
  accuracy
      ->add_option("--effects", o.effects,
                   "Effect sets: elastic, viscoelastic, viscoplastic, fibres")
      ->delimiter(',')
      ->capture_default_str();
  accuracy
      ->add_option("--integrators", o.integrators,
                   "central-difference, rk4, dopri5, backward-euler, bdf2")
      ->delimiter(',')
      ->capture_default_str();
  accuracy->add_option("--steps-ms", o.steps_ms, "Steps of the fixed-step schemes (ms)")
      ->delimiter(',')
      ->capture_default_str();
  accuracy->add_option("--tolerances", o.study.tolerances_m, "dopri5 tolerances (m)")
      ->delimiter(',')
      ->capture_default_str();
  accuracy->add_option("--duration", o.study.duration_s, "Simulated time of each run (s)")
      ->capture_default_str();
  accuracy->add_option("--force", o.study.peak_force_n, "Peak tension (N)")->capture_default_str();
  accuracy
      ->add_option("--refinement", o.study.reference_refinement,
                   "Reference step = smallest step / this")
      ->capture_default_str();
  accuracy
      ->add_option("--output-dir", o.output_dir, "Where accuracy-study.md, its CSV and images/ go")
      ->capture_default_str();
  accuracy->add_flag("!--no-plots", o.plots, "Skip the PNG plots (they need X or xvfb-run)");

  const auto run_stability = add_stability_study(*study);

  return [options, accuracy, run_stability]() -> std::optional<int> {
    if (auto exit_code = run_stability()) return exit_code;
    if (!accuracy->parsed()) return std::nullopt;
    // The exact command that produced the report, for the report itself.
    options->command_line = "liversim-cli study accuracy";
    const StudyCommandOptions& o = *options;
    std::ostringstream args;
    auto list = [&](const char* flag, const auto& values) {
      args << ' ' << flag << ' ';
      for (std::size_t i = 0; i < values.size(); ++i) args << (i ? "," : "") << values[i];
    };
    list("--tets", o.study.tet_counts);
    list("--effects", o.effects);
    list("--integrators", o.integrators);
    list("--steps-ms", o.steps_ms);
    list("--tolerances", o.study.tolerances_m);
    args << " --duration " << o.study.duration_s << " --force " << o.study.peak_force_n
         << " --refinement " << o.study.reference_refinement;
    options->command_line += args.str();
    return guarded([&] { return run_study(*options); });
  };
}

}  // namespace liversim::cli
