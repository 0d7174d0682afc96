#include "cut_bench_command.h"

#include "liversim/core/cutting.h"
#include "liversim/core/default_scene.h"
#include "liversim/core/surface_bvh.h"
#include "liversim/core/worker_pool.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <vector>

namespace liversim::cli {
namespace {

struct CutBenchOptions {
  int tets = 10583;
  double step_mm = 2.0;
  double stroke_mm = 120.0;
  std::filesystem::path output_dir = "docs";
  int threads = 2;
};

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto at = static_cast<std::size_t>(p * static_cast<double>(values.size() - 1) + 0.5);
  return values[std::min(at, values.size() - 1)];
}

int run(const CutBenchOptions& o) {
  using clock = std::chrono::steady_clock;
  auto ms = [](clock::time_point a, clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  const SceneSetup scene = default_scene(o.tets);
  auto model = std::make_shared<const SimModel>(build_model(scene.mesh, scene.model_options));
  // The threads the state's loops run on (the workstation's run on both cores).
  auto workers = o.threads > 1 ? std::make_shared<WorkerPool>(o.threads) : nullptr;
  SimState state = make_rest_state(*model, workers);
  const double start_step_s = model->stable_time_step_s;
  const std::size_t start_tets = model->tet_count;
  Eigen::AlignedBox3d box;
  for (std::size_t n = 0; n < model->node_count; ++n) box.extend(model->rest_position_m.at(n));
  const Eigen::Vector3d centre = box.center();

  // A vertical blade drawn along the liver's length through its whole depth, the cut updated
  // at every step of the stroke (as the workstation does once per interval).
  CuttingSettings settings;
  settings.cutting_stress_pa = 0.0;
  BladeStroke stroke;
  std::vector<double> all_ms, cutting_ms, cut_ms, surface_ms, bvh_ms;
  std::size_t separated = 0, duplicated = 0, snapped = 0;
  const int steps = static_cast<int>(o.stroke_mm / o.step_mm);
  for (int k = 0; k <= steps; ++k) {
    const double x = centre.x() - 0.5e-3 * o.stroke_mm + 1e-3 * o.step_mm * k;
    stroke.add({Eigen::Vector3d(x, centre.y(), box.max().z() + 0.01),
                Eigen::Vector3d(x, centre.y(), box.min().z() - 0.01)});
    const auto t0 = clock::now();
    CutResult cut = cut_tissue(*model, state, stroke, settings);
    const auto t1 = clock::now();
    cut_ms.push_back(ms(t0, t1));
    if (!cut.cut()) {
      all_ms.push_back(ms(t0, t1));
      continue;
    }
    const BoundarySurface surface = boundary_surface(*cut.model);
    const auto t2 = clock::now();
    const SurfaceBvh bvh(surface, cut.state.position_m);
    const auto t3 = clock::now();
    surface_ms.push_back(ms(t1, t2));
    bvh_ms.push_back(ms(t2, t3));
    all_ms.push_back(ms(t0, t3));
    cutting_ms.push_back(ms(t0, t3));
    separated += cut.report.separated_faces;
    duplicated += cut.report.duplicated_nodes;
    snapped += cut.report.snapped_nodes;
    model = cut.model;
    state = std::move(cut.state);
  }

  std::ostringstream command;
  command << "liversim-cli bench-cut --tets " << o.tets << " --step-mm " << o.step_mm
          << " --stroke-mm " << o.stroke_mm << " --threads " << o.threads;
  std::ostringstream doc;
  doc << "# Cutting: cost of a stroke's updates\n\n"
      << "Measured by `" << command.str() << "` (release build; the state's loops on " << o.threads
      << " thread(s), as the workstation's run on both cores). A vertical blade is\n"
      << "drawn " << o.stroke_mm << " mm along the built-in liver (" << start_tets
      << " tetrahedra) through its whole depth in steps of " << o.step_mm
      << " mm; after each step the cut is\n"
      << "updated with the stroke so far (`cut_tissue`), and when it changed the mesh the surface "
         "is\n"
      << "read again (`boundary_surface`) and the contact hierarchy rebuilt. The cutting threshold "
         "is 0 (the blade "
         "cuts\n"
      << "whatever it passes through). Target (issue 7): one update within a frame, 16 ms.\n\n"
      << std::fixed << std::setprecision(2)
      << "| part | updates | median (ms) | 95th percentile (ms) | max (ms) |\n"
      << "|---|---:|---:|---:|---:|\n";
  auto row = [&](const char* name, const std::vector<double>& v) {
    doc << "| " << name << " | " << v.size() << " | " << percentile(v, 0.5) << " | "
        << percentile(v, 0.95) << " | " << (v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()))
        << " |\n";
  };
  row("every update (cut, and surface and hierarchy when it cut)", all_ms);
  row("updates that cut, whole", cutting_ms);
  row("`cut_tissue` alone, every update", cut_ms);
  row("surface (`boundary_surface`), updates that cut", surface_ms);
  row("hierarchy build, updates that cut", bvh_ms);
  doc << "\nOver the stroke: " << separated << " faces separated, " << duplicated
      << " node copies, " << snapped << " nodes snapped onto the cut; " << model->tet_count
      << " tetrahedra after. The stable explicit step went from " << std::setprecision(3)
      << start_step_s * 1e3 << " ms to " << model->stable_time_step_s * 1e3
      << " ms (the cut's local modes, see docs/cutting.md).\n";
  std::filesystem::create_directories(o.output_dir);
  const auto path = o.output_dir / "cutting-performance.md";
  std::ofstream out(path);
  if (!out) {
    std::cerr << "cannot write " << path << "\n";
    return 1;
  }
  out << doc.str();
  std::cout << doc.str();
  return out ? 0 : 1;
}

}  // namespace

std::function<std::optional<int>()> add_cut_bench_command(CLI::App& app) {
  auto options = std::make_shared<CutBenchOptions>();
  auto* command = app.add_subcommand(
      "bench-cut", "Time the cut updates of a scalpel stroke; writes cutting-performance.md");
  command->add_option("--tets", options->tets, "Element count of the built-in liver")
      ->check(CLI::Range(100, 2'000'000))
      ->capture_default_str();
  command->add_option("--step-mm", options->step_mm, "Blade travel between updates (mm)")
      ->check(CLI::Range(0.01, 100.0))
      ->capture_default_str();
  command->add_option("--stroke-mm", options->stroke_mm, "Length of the stroke (mm)")
      ->check(CLI::Range(1.0, 1000.0))
      ->capture_default_str();
  command->add_option("--threads", options->threads, "Threads of the state's loops")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  command->add_option("--output-dir", options->output_dir, "Where cutting-performance.md goes")
      ->capture_default_str();
  return [command, options]() -> std::optional<int> {
    if (!command->parsed()) return std::nullopt;
    return run(*options);
  };
}

}  // namespace liversim::cli
