#include "render_bench_command.h"

#include "cli_commands.h"

#include "liversim/meshing/default_scene.h"
#include "liversim/meshing/liver_geometry.h"

#ifdef LIVERSIM_HAVE_RENDER
#include "render/liver_scene.h"
#include "render/offscreen_png.h"

#include <vtkNew.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#endif

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace liversim::cli {
namespace {

struct RenderBenchOptions {
  std::vector<int> tet_counts{kDefaultLiverTetCount, 10583};
  int frames = 300;
  int width = 1280;
  int height = 800;
  std::filesystem::path output_dir = "docs";
};

#ifdef LIVERSIM_HAVE_RENDER

// The workstation's display timer fires every 16 ms: the frame rate a frame must keep up with.
constexpr double kDisplayRateHz = 60.0;
// Below this the motion no longer looks continuous: an effect that costs that much stays off.
constexpr double kSmoothMotionHz = 30.0;
// Frames drawn before timing: the first compile the shaders and allocate the buffers.
constexpr int kWarmUpFrames = 10;
// The surface's motion repeats every second of the display's frames.
constexpr int kMotionFrames = 60;
// How far the left lobe's tip rises and falls: a firm pull's displacement.
constexpr double kLiftAmplitude_m = 0.015;

struct FrameTimes {
  std::vector<double> frame_ms;   // update_positions + render, to the GPU's completion
  std::vector<double> update_ms;  // update_positions alone
};

double frames_per_second(const FrameTimes& times) {
  double total_ms = 0.0;
  for (double ms : times.frame_ms) total_ms += ms;
  return 1e3 * static_cast<double>(times.frame_ms.size()) / total_ms;
}

// One second of a moving liver: the left lobe (the organ's +x end) lifted and lowered, more the
// farther out, as a grab at its tip would move it. Made before timing, so that a frame's time is
// the scene's update and draw only, as in the workstation (whose simulation runs on other threads).
std::vector<NodeArray> lobe_motion(const NodeArray& rest_m) {
  double min_x = INFINITY, max_x = -INFINITY;
  for (std::size_t n = 0; n < rest_m.size(); ++n) {
    min_x = std::min(min_x, rest_m.at(n).x());
    max_x = std::max(max_x, rest_m.at(n).x());
  }
  std::vector<NodeArray> frames;
  for (int k = 0; k < kMotionFrames; ++k) {
    const double lift_m = kLiftAmplitude_m * std::sin(2.0 * std::numbers::pi * k / kMotionFrames);
    NodeArray moved = rest_m;
    for (std::size_t n = 0; n < rest_m.size(); ++n) {
      const double along = (rest_m.at(n).x() - min_x) / (max_x - min_x);
      moved.set(n, rest_m.at(n) + Eigen::Vector3d(0.0, lift_m * along * along, 0.0));
    }
    frames.push_back(std::move(moved));
  }
  return frames;
}

FrameTimes time_frames(LiverScene& scene, vtkRenderWindow* window,
                       const std::vector<NodeArray>& motion, int frames) {
  using clock = std::chrono::steady_clock;
  const auto ms = [](clock::time_point a, clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  FrameTimes times;
  for (int k = -kWarmUpFrames; k < frames; ++k) {
    const auto t0 = clock::now();
    scene.update_positions(motion[static_cast<std::size_t>(k + kWarmUpFrames) % motion.size()]);
    const auto t1 = clock::now();
    window->Render();
    // The draw is finished, not only queued: what the display would wait for.
    window->WaitForCompletion();
    const auto t2 = clock::now();
    if (k < 0) continue;
    times.update_ms.push_back(ms(t0, t1));
    times.frame_ms.push_back(ms(t0, t2));
  }
  return times;
}

// "OpenGL renderer string: NAME" of the window's capabilities report.
std::string renderer_name(vtkRenderWindow* window) {
  const std::string report = window->ReportCapabilities();
  const std::string key = "OpenGL renderer string:";
  const auto at = report.find(key);
  if (at == std::string::npos) return "unknown renderer";
  const auto end = report.find('\n', at);
  std::string name =
      report.substr(at + key.size(), end == std::string::npos ? end : end - at - key.size());
  name.erase(0, name.find_first_not_of(' '));
  return name;
}

struct BenchRow {
  std::string liver;
  std::string view;
  bool occlusion = false;
  FrameTimes times;
};

int run(const RenderBenchOptions& o) {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0')
    return fail(
        "render-bench needs an X display (DISPLAY is unset); run the command inside xvfb-run -a");
  std::vector<BenchRow> rows;
  std::string renderer = "unknown renderer";
  int multisamples = 0;
  std::ostringstream livers;
  for (int tets : o.tet_counts) {
    const SceneSetup setup = default_scene(tets);
    LiverScene scene(setup.mesh, setup.visual);
    // A lesion of 15 mm radius in the organ's middle, for the see-through view to show.
    Eigen::AlignedBox3d box;
    for (std::size_t n = 0; n < setup.mesh.node_count(); ++n)
      box.extend(setup.mesh.rest_position_m.at(n));
    scene.show_lesions({{box.center(), Eigen::Vector3d::Constant(0.015)}});
    const std::vector<NodeArray> motion = lobe_motion(setup.mesh.rest_position_m);

    vtkNew<vtkRenderWindow> window;
    use_shared_x_connection(window);  // one liver's window closes before the next opens
    window->SetOffScreenRendering(1);
    window->SetSize(o.width, o.height);
    window->AddRenderer(scene.renderer());
    scene.reset_camera(static_cast<double>(o.width) / o.height);
    window->Render();
    renderer = renderer_name(window);
    multisamples = window->GetMultiSamples();

    const std::string liver = setup.description;
    livers << "- " << liver << ": " << setup.visual.vertex_count() << " surface vertices, "
           << setup.visual.surface.triangles.size() << " triangles; the lesion shows "
           << scene.shown_lesion_triangle_count() << " triangles.\n";
    for (const bool see_through : {false, true}) {
      scene.set_opacity(see_through ? kSeeThroughOpacity : 1.0);
      for (const bool occlusion : {false, true}) {
        scene.set_ambient_occlusion(occlusion);
        BenchRow row{liver, see_through ? "see-through" : "solid", occlusion,
                     time_frames(scene, window, motion, o.frames)};
        std::cout << liver << ", " << row.view << ", ambient occlusion "
                  << (occlusion ? "on" : "off") << ": " << format(frames_per_second(row.times), 3)
                  << " fps\n";
        rows.push_back(std::move(row));
      }
    }
    scene.set_ambient_occlusion(false);
    window->RemoveRenderer(scene.renderer());
  }

  std::ostringstream command;
  command << "liversim-cli render-bench --tets ";
  for (std::size_t i = 0; i < o.tet_counts.size(); ++i)
    command << (i ? "," : "") << o.tet_counts[i];
  command << " --frames " << o.frames << " --width " << o.width << " --height " << o.height;
  const bool software = renderer.find("llvmpipe") != std::string::npos ||
                        renderer.find("softpipe") != std::string::npos;

  std::ostringstream md;
  md << "# Rendering: frame rate\n\n"
     << written_by(command.str()) << "\n\nRelease build. Renderer: " << renderer
     << (software ? " — Mesa's software rasteriser, which is what Xvfb offers: no graphics "
                    "card draws here, the processor does, sharing its cores with whatever else "
                    "runs"
                  : "")
     << ".\n\n"
     << "Each liver is drawn offscreen at " << o.width << " × " << o.height << " pixels ("
     << multisamples << " multisamples, the render window's default, as in the workstation) for "
     << o.frames << " timed frames after " << kWarmUpFrames
     << " untimed ones. Every frame moves the surface as the workstation does "
        "(`LiverScene::update_positions`: the left lobe lifted and lowered by up to "
     << kLiftAmplitude_m * 1e3
     << " mm over a second), draws it and waits for the draw to finish. A frame's time is both; "
        "the last column is the update alone. The see-through view is the organ at opacity "
     << kSeeThroughOpacity << " with a lesion of 15 mm radius inside.\n\n"
     << livers.str() << "\n"
     << "| liver | view | ambient occlusion | frames/s | median frame (ms) | 95th percentile (ms) "
        "| update_positions, median (ms) |\n"
     << "|---|---|---|---:|---:|---:|---:|\n";
  for (const BenchRow& row : rows)
    md << "| " << row.liver << " | " << row.view << " | " << (row.occlusion ? "on" : "off") << " | "
       << format(frames_per_second(row.times), 3) << " | "
       << format(percentile(row.times.frame_ms, 0.5), 3) << " | "
       << format(percentile(row.times.frame_ms, 0.95), 3) << " | "
       << format(percentile(row.times.update_ms, 0.5), 3) << " |\n";

  // The verdict on the default liver's solid view, the one the trainee works on.
  const auto fps_of = [&](bool occlusion) {
    for (const BenchRow& row : rows)
      if (row.view == "solid" && row.occlusion == occlusion) return frames_per_second(row.times);
    return 0.0;
  };
  const double without = fps_of(false), with = fps_of(true);
  md << "\n## Ambient occlusion at frame rate\n\n"
     << "Target: the workstation's display timer, " << kDisplayRateHz << " Hz (16 ms a frame). On "
     << rows.front().liver << ", solid, this machine draws " << format(without, 3)
     << " frames/s without ambient occlusion and " << format(with, 3) << " with it. ";
  if (with >= kDisplayRateHz)
    md << "Ambient occlusion keeps the display rate here: it is affordable.";
  else if (with >= kSmoothMotionHz)
    md << "Ambient occlusion stays above " << kSmoothMotionHz
       << " frames/s but below the display rate: it is affordable where smooth motion matters "
          "less than the picture, and stays off by default.";
  else
    md << "Ambient occlusion falls below " << kSmoothMotionHz
       << " frames/s here, where motion stops looking continuous: it stays off by default and is "
          "offered as an option (`LiverScene::set_ambient_occlusion`).";
  if (without < kDisplayRateHz)
    md << " Without it the picture already misses the display rate on this machine"
       << (software ? ", whose processor draws every pixel (no graphics card was measured)" : "")
       << ".";
  md << "\n";
  std::cout << md.str();
  std::filesystem::create_directories(o.output_dir);
  return write_report(o.output_dir / "rendering-performance.md", md.str());
}

#else

int run(const RenderBenchOptions&) {
  return fail("this liversim-cli was built without the renderer (LIVERSIM_BUILD_UI=OFF)");
}

#endif

}  // namespace

std::function<std::optional<int>()> add_render_bench_command(CLI::App& app) {
  auto options = std::make_shared<RenderBenchOptions>();
  auto* command = app.add_subcommand(
      "render-bench",
      "Time the liver's frames (solid and see-through, ambient occlusion off and on) in an "
      "offscreen window; writes rendering-performance.md (needs X or xvfb-run)");
  command->add_option("--tets", options->tet_counts, "Built-in liver sizes drawn")
      ->delimiter(',')
      ->check(CLI::Range(100, 2'000'000))
      ->capture_default_str();
  command->add_option("--frames", options->frames, "Timed frames of each view")
      ->check(CLI::Range(1, 100'000))
      ->capture_default_str();
  command->add_option("--width", options->width, "Window width (pixels)")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  command->add_option("--height", options->height, "Window height (pixels)")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  command->add_option("--output-dir", options->output_dir, "Where rendering-performance.md goes")
      ->capture_default_str();
  return [command, options]() -> std::optional<int> {
    if (!command->parsed()) return std::nullopt;
    return guarded([&] { return run(*options); });
  };
}

}  // namespace liversim::cli
