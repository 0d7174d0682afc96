#include "cli_commands.h"

#include "liversim/core/default_scene.h"
#include "liversim/core/grab.h"
#include "liversim/core/integrator.h"
#include "liversim/core/mesh_io.h"
#include "liversim/core/mesh_quality.h"
#include "liversim/core/state.h"
#include "liversim/core/surface.h"

#ifdef LIVERSIM_HAVE_RENDER
#include "render/liver_scene.h"
#endif

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <stdexcept>
#include <vector>

namespace liversim::cli {
namespace {

int fail(const std::string& message) {
  std::cerr << "liversim-cli: error: " << message << "\n";
  return 2;
}

SceneSetup load_scene(const MeshSource& source) {
  if (source.file) return scene_from_file(*source.file, source.fixed_set);
  if (source.fixed_set) throw std::invalid_argument("--fixed-set needs --mesh");
  return default_scene(source.tet_count);
}

// Runs `body` and turns the exceptions of bad input into an error message and exit code 2.
template <typename Body>
int guarded(Body&& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    return fail(e.what());
  }
}

}  // namespace

int mesh_report(const MeshSource& mesh) {
  return guarded([&] {
    const SceneSetup scene = load_scene(mesh);
    std::cout << scene.description << "\n" << assess_quality(scene.mesh);
    std::cout << "fixed nodes " << scene.model_options.fixed_nodes.size() << "\n";
    std::vector<double> visual_xyz;
    map_visual_positions(scene.visual, scene.mesh.rest_position_m, visual_xyz);
    double gap_sum = 0.0, gap_max = 0.0;
    for (std::size_t v = 0; v < scene.visual.vertex_count(); ++v) {
      const Eigen::Vector3d vertex(visual_xyz[3 * v], visual_xyz[3 * v + 1], visual_xyz[3 * v + 2]);
      const double gap =
          (vertex - scene.mesh.rest_position_m.at(scene.visual.surface.nodes[v])).norm();
      gap_sum += gap;
      gap_max = std::max(gap_max, gap);
    }
    std::cout << std::fixed << std::setprecision(2)
              << "rendered surface off the physics boundary nodes: mean "
              << 1e3 * gap_sum / std::max<std::size_t>(scene.visual.vertex_count(), 1)
              << " mm, max " << 1e3 * gap_max << " mm\n";
    const SimModel model = build_model(scene.mesh, scene.model_options);
    std::cout << std::fixed << std::setprecision(0) << "highest frequency at rest "
              << model.max_frequency_rad_per_s << " rad/s; explicit central-difference step "
              << std::setprecision(3) << model.stable_time_step_s * 1e3 << " ms ("
              << std::setprecision(2) << model.stable_step_safety
              << " x 2/omega, E = " << std::setprecision(0)
              << model.regions[0].tissue.youngs_modulus_pa << " Pa, nu = " << std::setprecision(3)
              << model.regions[0].tissue.poisson_ratio << ")\n";
    return 0;
  });
}

int simulate(const SimulateOptions& options) {
  return guarded([&]() -> int {
    if (!options.force_n.allFinite()) return fail("--force must be three finite numbers");
    const SceneSetup scene = load_scene(options.mesh);
    const SimModel model = build_model(scene.mesh, scene.model_options);
    const NodeIndex node = options.node.value_or(anterior_marked_node(scene.mesh));
    if (node < 0 || static_cast<std::size_t>(node) >= model.node_count)
      return fail("--node " + std::to_string(node) + " is outside the mesh (" +
                  std::to_string(model.node_count) + " nodes, numbered from 0)");
    if (model.is_fixed[node]) return fail("--node " + std::to_string(node) + " is a fixed node");

    // Spread the load with the same bump weights a grab uses (weights sum to 1).
    const Grab patch =
        grab_surface(extract_surface(scene.mesh), scene.mesh.rest_position_m, model.lumped_mass_kg,
                     scene.mesh.rest_position_m.at(node), options.load_radius_m, 1.0);
    std::vector<PointLoad> loads;
    for (std::size_t i = 0; i < patch.nodes.size(); ++i)
      loads.push_back({patch.nodes[i], options.force_n * patch.stiffness_n_per_m[i]});
    const StepInputs inputs{loads, {}};

    std::ofstream csv;
    if (options.csv_output) {
      csv.open(*options.csv_output);
      if (!csv) return fail("cannot write " + options.csv_output->string());
      csv << "time_s,ux_m,uy_m,uz_m\n";
    }
    SimState state = make_rest_state(model);
    const Eigen::Vector3d rest = model.rest_position_m.at(node);
    auto write_sample = [&] {
      const Eigen::Vector3d u = state.position_m.at(node) - rest;
      if (csv) csv << state.time_s << "," << u.x() << "," << u.y() << "," << u.z() << "\n";
    };
    write_sample();
    const auto wall_start = std::chrono::steady_clock::now();
    const int samples =
        std::max(1, static_cast<int>(std::ceil(options.duration_s / options.sample_interval_s)));
    double smallest_step = options.duration_s, largest_step = 0.0, stiffening = 1.0;
    for (int i = 0; i < samples; ++i) {
      const StepReport report = advance(model, state, inputs, options.duration_s / samples);
      smallest_step = std::min(smallest_step, report.smallest_substep_s);
      largest_step = std::max(largest_step, report.largest_substep_s);
      stiffening = std::max(stiffening, report.max_stiffening);
      write_sample();
    }
    const double wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    const Eigen::Vector3d u = state.position_m.at(node) - rest;
    if (!u.allFinite()) return fail("the simulation diverged (non-finite displacement)");

    std::cout << std::setprecision(6) << scene.description << "; load "
              << options.force_n.transpose() << " N on node " << node << " spread over "
              << patch.nodes.size() << " surface nodes\n"
              << "explicit central difference: " << state.step_count << " steps of "
              << smallest_step * 1e3 << " to " << largest_step * 1e3 << " ms (rest stable step "
              << model.stable_time_step_s * 1e3 << " ms; compression stiffened it up to "
              << stiffening << "x), " << wall_s << " s wall time\n"
              << "displacement of node " << node << " after " << state.time_s
              << " s (mm): " << (u * 1e3).transpose() << "  |u| = " << u.norm() * 1e3 << "\n";
    if (csv) std::cout << "wrote " << options.csv_output->string() << "\n";
    return 0;
  });
}

#ifdef LIVERSIM_HAVE_RENDER
int screenshot(const ScreenshotOptions& options) {
  return guarded([&] {
    const SceneSetup scene = load_scene(options.mesh);
    LiverScene view(scene.mesh, scene.visual);
    write_screenshot_png(view, options.output, options.width, options.height);
    std::cout << "wrote " << options.output.string() << " (" << scene.description << ")\n";
    return 0;
  });
}

int demo(const ScreenshotOptions& options) {
  return guarded([&] {
    const SceneSetup scene = load_scene(options.mesh);
    const SimModel model = build_model(scene.mesh, scene.model_options);
    const NodeIndex node = anterior_marked_node(scene.mesh);
    const BoundarySurface& surface = scene.visual.surface;
    // Grab the anterior point and pull it 3 cm forward and down over 0.3 s, then hold.
    const Eigen::Vector3d grabbed = scene.mesh.rest_position_m.at(node);
    const Grab grab = grab_surface(surface, scene.mesh.rest_position_m, model.lumped_mass_kg,
                                   grabbed, 0.02, 300.0);
    SimState state = make_rest_state(model);
    std::vector<NodeSpring> springs;
    const Eigen::Vector3d pull(0.0, -0.02, 0.03);
    constexpr int kFrames = 30;
    for (int frame = 1; frame <= kFrames; ++frame) {
      const double ramp = std::min(1.0, frame / 18.0);
      grab_springs(grab, grabbed + ramp * pull, springs);
      advance(model, state, StepInputs{{}, springs}, 1.0 / 60.0);
    }
    const Eigen::Vector3d handle = grabbed + pull;
    const Eigen::Vector3d force = grab_reaction_force_n(grab, handle, state.position_m);
    LiverScene view(scene.mesh, scene.visual);
    view.update_positions(state.position_m);
    view.show_grab_marker(handle);
    write_screenshot_png(view, options.output, options.width, options.height);
    std::cout << "demo: pulled " << scene.description << " by " << pull.norm() * 1e3 << " mm for "
              << state.time_s << " s; grabbed point moved "
              << (state.position_m.at(node) - grabbed).norm() * 1e3 << " mm; tool force "
              << force.norm() << " N\nwrote " << options.output.string() << "\n";
    return 0;
  });
}
#else
int screenshot(const ScreenshotOptions&) {
  return fail("this liversim-cli was built without the renderer (LIVERSIM_BUILD_UI=OFF)");
}
int demo(const ScreenshotOptions& options) {
  return screenshot(options);
}
#endif

}  // namespace liversim::cli
