#include "stability_command.h"

#include "cli_commands.h"

#include "liversim/engine/parameter_ranges.h"
#include "liversim/studies/stability_suite.h"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace liversim::cli {
namespace {

struct StabilityStudyOptions {
  std::vector<std::string> cases;  // empty: all
  StabilitySuiteOptions suite;
  std::filesystem::path output_dir = "docs";
};

std::string verdict(const StabilityRun& run) {
  return run.passed() ? "pass" : "**FAIL**";
}

std::string command_line(const StabilityStudyOptions& o) {
  std::ostringstream line;
  line << "liversim-cli study stability";
  for (const std::string& name : o.cases) line << " --case " << name;
  if (!o.suite.shared_data_dir.empty())
    line << " --shared-data " << o.suite.shared_data_dir.string();
  line << " --long-run " << o.suite.long_run_s << " --sweep-samples " << o.suite.sweep_samples
       << " --sweep-seed " << o.suite.sweep_seed;
  return line.str();
}

int run_suite(const StabilityStudyOptions& o) {
  std::vector<const StabilityCase*> chosen;
  for (const std::string& name : o.cases) {
    const StabilityCase* c = find_stability_case(name);
    if (!c) {
      std::string known;
      for (const StabilityCase& k : stability_cases()) known += std::string(" ") += k.name;
      return fail("unknown stability case '" + name + "': expected one of" + known);
    }
    chosen.push_back(c);
  }
  if (chosen.empty())
    for (const StabilityCase& c : stability_cases()) chosen.push_back(&c);
  std::filesystem::create_directories(o.output_dir);

  std::ostringstream table, checks;
  table << "| case | run | scheme | simulated (s) | steps | smallest step (ms) | rollbacks "
           "| energy created | dissipated at the end | largest displacement (mm) | wall (s) | "
           "verdict |\n"
           "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
  int failed = 0, total = 0;
  for (const StabilityCase* c : chosen) {
    std::cerr << "case " << c->number << " " << c->name << " ..." << std::endl;
    const std::vector<StabilityRun> runs = run_stability_case(*c, o.suite);
    checks << "\n### " << c->number << ". " << c->title << " (`" << c->name << "`)\n";
    for (const StabilityRun& run : runs) {
      ++total;
      if (!run.passed()) ++failed;
      std::cout << c->number << " " << c->name << " / " << run.variant << ": " << verdict(run)
                << " (" << run.steps.substeps << " steps, " << run.rollbacks << " rollbacks, "
                << format(run.wall_time_s) << " s)" << std::endl;
      table << "| " << c->number << " " << c->name << " | " << run.variant << " | "
            << run.integrator << " | " << format(run.simulated_s, 4) << " | " << run.steps.substeps
            << " | " << format(run.steps.smallest_substep_s * 1e3) << " | " << run.rollbacks
            << " | " << format(100.0 * run.energy_error, 2) << " % | "
            << (run.energy_supplied_j > 0.0
                    ? format(100.0 * (1.0 - run.energy_held_j / run.energy_supplied_j), 3) + " %" +
                          (run.viscous_dissipated_j > 0.0
                               ? " (viscous " +
                                     format(
                                         100.0 * run.viscous_dissipated_j / run.energy_supplied_j,
                                         3) +
                                     " %)"
                               : std::string())
                    : std::string("–"))
            << " | " << format(run.max_displacement_m * 1e3) << " | " << format(run.wall_time_s)
            << " | " << verdict(run) << " |\n";
      checks << "\n"
             << run.variant << (run.integrator.empty() ? "" : " (" + run.integrator + ")") << ": "
             << verdict(run) << "\n\n";
      if (!run.error.empty()) checks << "- error: " << run.error << "\n";
      if (!run.last_problem.empty())
        checks << "- last problem the guard met: " << run.last_problem << "\n";
      for (const StabilityCheck& check : run.checks)
        checks << "- " << check.what << ": " << format(check.value, 4) << " "
               << (check.at_most ? "≤" : "≥") << " " << format(check.limit, 4) << " — "
               << (check.passed() ? "pass" : "**FAIL**") << "\n";
    }
  }

  std::ostringstream md;
  md << "# Stability suite report\n\n"
     << written_by(command_line(o))
     << "\n\nOne hardware thread used; wall times are of that run. The cases, their checks and "
        "where each limit comes from are in [stability.md](stability.md) and "
        "`core/studies/src/stability_case*.cpp`. Energy created: the largest energy created over "
        "the run "
        "as "
        "a fraction of the energy supplied (initial + work of loads and tools), 0 when the books "
        "showed only dissipation; dissipated: the share of the energy supplied that viscosity, "
        "plasticity, damping and the scheme took out by the end (in brackets, the Maxwell arms' "
        "dashpots alone). Steps: accepted integrator "
        "steps.\n\n"
     << total - failed << " of " << total << " runs passed.\n\n"
     << table.str() << "\n## Checks\n"
     << checks.str()
     << "\n## Parameter ranges (case 12 samples them; "
        "`core/engine/include/liversim/engine/parameter_ranges.h`)\n\n"
     << "| parameter | key | from | to | unit | sampled | why |\n|---|---|---:|---:|---|---|---|\n";
  for (const ParameterRange& range : tissue_parameter_ranges())
    md << "| " << range.label << " | `" << range.name << "` | " << format(range.min, 4) << " | "
       << format(range.max, 4) << " | " << range.unit << " | "
       << (!range.swept      ? "no (no force of the sweep uses it)"
           : range.log_scale ? "log-uniform"
                             : "uniform")
       << " | " << range.why << " |\n";
  if (const int written = write_report(o.output_dir / "stability-report.md", md.str()))
    return written;
  return failed == 0 ? 0 : 1;
}

}  // namespace

std::function<std::optional<int>()> add_stability_study(CLI::App& study) {
  auto options = std::make_shared<StabilityStudyOptions>();
  auto* stability = study.add_subcommand(
      "stability",
      "Run the stability suite's hard cases and write docs/stability-report.md (exit code 1 when "
      "a check fails)");
  StabilityStudyOptions& o = *options;
  stability->add_option("--case", o.cases, "Case to run (repeatable; default: every case)");
  stability
      ->add_option("--shared-data", o.suite.shared_data_dir,
                   "../shared/data, for the cases on external meshes (skipped without it)")
      ->check(CLI::ExistingDirectory);
  stability->add_option("--long-run", o.suite.long_run_s, "Free run of case 9 (s)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  stability->add_option("--sweep-samples", o.suite.sweep_samples, "Samples of case 12")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  stability->add_option("--sweep-seed", o.suite.sweep_seed, "Seed of case 12's sweep")
      ->capture_default_str();
  stability->add_option("--output-dir", o.output_dir, "Where stability-report.md goes")
      ->capture_default_str();
  return [options, stability]() -> std::optional<int> {
    if (!stability->parsed()) return std::nullopt;
    return guarded([&] { return run_suite(*options); });
  };
}

}  // namespace liversim::cli
