#include "cut_bench_command.h"

#include "cli_commands.h"
#include "live_cut_bench.h"

#include "liversim/engine/model_building.h"
#include "liversim/engine/surface_bvh.h"
#include "liversim/engine/worker_pool.h"
#include "liversim/interaction/cutting.h"
#include "liversim/meshing/default_scene.h"

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

// Issue 7's target: one cut update within a frame of the display (60 Hz).
constexpr double kFrameMs = 16.0;

struct CutBenchOptions {
  int tets = 10583;
  double step_mm = 2.0;
  double stroke_mm = 120.0;
  std::filesystem::path output_dir = "docs";
  int threads = 2;
  int repeats = 5;
};

int run(const CutBenchOptions& o) {
  using clock = std::chrono::steady_clock;
  auto ms = [](clock::time_point a, clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  const SceneSetup scene = default_scene(o.tets);
  const auto start_model =
      std::make_shared<const SimModel>(build_model(scene.mesh, scene.model_options));
  // The threads the state's loops run on (the workstation's run on both cores).
  auto workers = o.threads > 1 ? std::make_shared<WorkerPool>(o.threads) : nullptr;
  const SimState start_state = make_rest_state(*start_model, workers);
  const double start_step_s = start_model->stable_time_step_s;
  const std::size_t start_tets = start_model->tet_count;
  Eigen::AlignedBox3d box;
  for (std::size_t n = 0; n < start_model->node_count; ++n)
    box.extend(start_model->rest_position_m.at(n));
  const Eigen::Vector3d centre = box.center();

  // A vertical blade drawn along the liver's length through its whole depth, the cut updated
  // at every step of the stroke (as the workstation does once per interval). The stroke is drawn
  // `repeats` times from the same start, making the same cuts each time; each update's times are
  // its fastest over the repeats, which leaves out what other work on the machine added.
  CuttingSettings settings;
  settings.cutting_stress_pa = 0.0;
  const int steps = static_cast<int>(o.stroke_mm / o.step_mm);
  // The whole update's fastest is its own minimum, not the sum of its parts' fastest.
  struct UpdateTimes {
    bool cut = false;
    double whole_ms = 0.0, cut_ms = 0.0, surface_ms = 0.0, bvh_ms = 0.0;
  };
  std::vector<UpdateTimes> fastest;
  std::shared_ptr<const SimModel> model;
  std::size_t separated = 0, duplicated = 0, snapped = 0;
  for (int repeat = 0; repeat < o.repeats; ++repeat) {
    model = start_model;
    SimState state = start_state;
    BladeStroke stroke;
    separated = duplicated = snapped = 0;
    for (int k = 0; k <= steps; ++k) {
      const double x = centre.x() - 0.5e-3 * o.stroke_mm + 1e-3 * o.step_mm * k;
      stroke.add({Eigen::Vector3d(x, centre.y(), box.max().z() + 0.01),
                  Eigen::Vector3d(x, centre.y(), box.min().z() - 0.01)});
      UpdateTimes times;
      const auto t0 = clock::now();
      CutResult cut = cut_stroke_so_far(*model, state, stroke, settings);
      const auto t1 = clock::now();
      times.cut_ms = times.whole_ms = ms(t0, t1);
      if ((times.cut = cut.cut())) {
        const BoundarySurface surface = boundary_surface(*cut.model);
        const auto t2 = clock::now();
        const SurfaceBvh bvh(surface, cut.state.position_m);
        const auto t3 = clock::now();
        times.surface_ms = ms(t1, t2);
        times.bvh_ms = ms(t2, t3);
        times.whole_ms = ms(t0, t3);
        separated += cut.report.separated_faces;
        duplicated += cut.report.duplicated_nodes;
        snapped += cut.report.snapped_nodes;
        model = cut.model;
        state = std::move(cut.state);
      }
      if (repeat == 0) {
        fastest.push_back(times);
        continue;
      }
      UpdateTimes& best = fastest[static_cast<std::size_t>(k)];
      if (best.cut != times.cut) {
        std::cerr << "bench-cut: update " << k << " cut on one repeat and not on another\n";
        return 1;
      }
      best.whole_ms = std::min(best.whole_ms, times.whole_ms);
      best.cut_ms = std::min(best.cut_ms, times.cut_ms);
      best.surface_ms = std::min(best.surface_ms, times.surface_ms);
      best.bvh_ms = std::min(best.bvh_ms, times.bvh_ms);
    }
  }
  std::vector<double> all_ms, cutting_ms, cut_ms, surface_ms, bvh_ms;
  for (const UpdateTimes& t : fastest) {
    all_ms.push_back(t.whole_ms);
    cut_ms.push_back(t.cut_ms);
    if (!t.cut) continue;
    cutting_ms.push_back(t.whole_ms);
    surface_ms.push_back(t.surface_ms);
    bvh_ms.push_back(t.bvh_ms);
  }

  std::ostringstream command;
  command << "liversim-cli bench-cut --tets " << o.tets << " --step-mm " << o.step_mm
          << " --stroke-mm " << o.stroke_mm << " --threads " << o.threads << " --repeats "
          << o.repeats;
  std::ostringstream doc;
  doc << "# Cutting: cost of a stroke's updates\n\n"
      << written_by(command.str()) << "\n\n"
      << "Release build; the state's loops on " << o.threads
      << " thread(s), as the workstation's run on both cores. A vertical blade is\n"
      << "drawn " << o.stroke_mm << " mm along the built-in liver (" << start_tets
      << " tetrahedra) through its whole depth in steps of " << o.step_mm
      << " mm; after each step the cut is\n"
      << "updated with the stroke so far as the real-time loop updates it (`cut_stroke_so_far`: "
         "the new\n"
      << "instant bent onto a groove it runs beside, then `cut_tissue`), and when it changed the "
         "mesh the surface is\n"
      << "read again (`boundary_surface`) and the contact hierarchy rebuilt. The cutting threshold "
         "is 0 (the blade "
         "cuts\n"
      << "whatever it passes through). The stroke is drawn " << o.repeats
      << " times from the same start (the same cuts each time); each update's times are its "
         "fastest of\n"
      << "those, so that other work on this shared machine does not count. Target (issue 7): one "
         "update\n"
      << "within a frame, " << kFrameMs << " ms.\n\n"
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
  row("`cut_stroke_so_far` alone, every update", cut_ms);
  row("surface (`boundary_surface`), updates that cut", surface_ms);
  row("hierarchy build, updates that cut", bvh_ms);
  const double slowest_ms = all_ms.empty() ? 0.0 : *std::max_element(all_ms.begin(), all_ms.end());
  doc << "\nThe slowest update took " << slowest_ms << " ms: the target is "
      << (slowest_ms <= kFrameMs ? "met" : "**not met**") << ".\n";
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
  command
      ->add_option("--repeats", options->repeats,
                   "Times the stroke is drawn; each update counts its fastest")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  command->add_option("--output-dir", options->output_dir, "Where cutting-performance.md goes")
      ->capture_default_str();
  auto live = std::make_shared<LiveCutBenchOptions>();
  auto live_asked = std::make_shared<bool>(false);
  command->add_flag(
      "--live", *live_asked,
      "Run --trajectory with a scalpel through the workstation's real-time loop instead, one "
      "run, every second and every cut update as they came; writes cutting-live.md");
  auto* trajectory = command->add_option(
      "--trajectory", live->trajectory,
      "--live: the scripted device's trajectory (device mm: time_s x_mm y_mm z_mm buttons "
      "[tool]; the first button arms the blade or closes the forceps; the hand holds the scalpel "
      "until the tool column says otherwise)");
  command->add_option("--scenario", live->scenario,
                      "--live: the scenario to cut (default: free practice at --tets)");
  auto* left_trajectory = command->add_option(
      "--left-trajectory", live->left_trajectory,
      "--live: a second scripted device, in the left hand (forceps holding the lobe while the "
      "scalpel cuts), in the same device frame as --trajectory");
  auto* left_tool = command
                        ->add_option("--left-tool", live->left_tool,
                                     "--live: what the left hand holds (hand, probe, forceps or "
                                     "scalpel) until its trajectory's tool column says otherwise")
                        ->capture_default_str();
  return [command, options, live, live_asked, trajectory, left_trajectory,
          left_tool]() -> std::optional<int> {
    if (!command->parsed()) return std::nullopt;
    const bool live_only =
        trajectory->count() > 0 || left_trajectory->count() > 0 || left_tool->count() > 0;
    if (!*live_asked && live_only)
      return fail("--trajectory, --left-trajectory and --left-tool go with --live");
    if (!*live_asked) return run(*options);
    if (trajectory->count() == 0) return fail("bench-cut --live needs --trajectory");
    if (left_tool->count() > 0 && left_trajectory->count() == 0)
      return fail("--left-tool needs --left-trajectory: the left hand's device plays it");
    live->tets = options->tets;
    live->output_dir = options->output_dir;
    return run_live_cut_bench(*live);
  };
}

}  // namespace liversim::cli
