#include "servo_bench_command.h"

#include "cli_commands.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/worker_pool.h"
#include "liversim/haptics/emulated_devices.h"
#include "liversim/haptics/servo_loop.h"
#include "liversim/interaction/cutting.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/simulation/realtime_simulation.h"

#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <numbers>
#include <sstream>
#include <thread>
#include <vector>

namespace liversim::cli {
namespace {

struct ServoBenchOptions {
  double seconds = 5.0;
  int runs = 3;
  int tets = 10583;
  std::filesystem::path output_dir = "docs";
};

// The probe's ball pressing 3 mm into the top of the liver and circling there (radius 10 mm, one
// turn every 2 s): device millimetres are scene millimetres (the default mapping).
std::vector<TrajectoryPoint> circle_on_top(const TetMesh& mesh, double seconds) {
  Eigen::AlignedBox3d box;
  for (std::size_t n = 0; n < mesh.node_count(); ++n) box.extend(mesh.rest_position_m.at(n));
  double top_m = -INFINITY;
  for (std::size_t n = 0; n < mesh.node_count(); ++n) {
    const Eigen::Vector3d p = mesh.rest_position_m.at(n);
    if ((p.head<2>() - box.center().head<2>()).norm() < 0.015) top_m = std::max(top_m, p.z());
  }
  const double ball_mm = Tool{}.geometry.probe_tip_radius_m * 1e3;
  const Eigen::Vector3d centre_mm(box.center().x() * 1e3, box.center().y() * 1e3,
                                  top_m * 1e3 + ball_mm - 3.0);
  std::vector<TrajectoryPoint> points;
  for (double t = 0.0; t <= seconds + 0.01; t += 0.01) {
    const double angle = std::numbers::pi * t;  // one turn every 2 s
    points.push_back(
        {t, centre_mm + 10.0 * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0), 0});
  }
  return points;
}

// alone: the servo and a publisher thread; simulation: with the real-time simulation, the probe in
// the device's hand; two_devices: with the simulation, a device in each hand holding a probe.
enum class Condition { alone, simulation, two_devices };

std::string condition_name(Condition condition) {
  switch (condition) {
    case Condition::alone:
      return "alone";
    case Condition::simulation:
      return "with the simulation";
    case Condition::two_devices:
      return "two devices, with the simulation";
  }
  return "";
}

struct ServoRun {
  Condition condition = Condition::alone;
  int run = 0;
  std::string device;  // the hand whose device it was, with two
  ServoStats stats;
};

// The left hand's device plays the same circle 4 cm to the left (−x) of the right hand's.
constexpr double kLeftHandOffsetM = -0.04;

std::vector<ServoRun> run_once(const SceneSetup& scene, Condition condition, int run,
                               double seconds) {
  const std::vector<TrajectoryPoint> circle = circle_on_top(scene.mesh, seconds);
  const Eigen::Vector3d circle_centre_m =
      (circle.front().position_mm - Eigen::Vector3d(10.0, 0.0, 0.0)) * 1e-3;
  TrajectoryDevice device("bench circle", circle);
  TrajectoryDevice left_device("bench circle, left hand", circle);
  ServoLoop::Options options;
  options.left_mapping.offset_m = {kLeftHandOffsetM, 0.0, 0.0};
  const bool two = condition == Condition::two_devices;
  std::unique_ptr<ServoLoop> servo = two ? std::make_unique<ServoLoop>(device, left_device, options)
                                         : std::make_unique<ServoLoop>(device, options);
  std::unique_ptr<RealtimeSimulation> simulation;
  std::atomic<bool> stop_publisher{false};
  std::thread publisher;
  if (condition != Condition::alone) {
    auto model = std::make_shared<const SimModel>(build_model(scene.mesh, scene.model_options));
    simulation = std::make_unique<RealtimeSimulation>(
        model, make_rest_state(*model, realtime_worker_pool()));
    simulation->enable_tools(boundary_surface(*model));
    simulation->set_haptic_servo(servo.get());
    simulation->set_device_tool(Hand::right, DeviceToolSettings{});
    if (two) simulation->set_device_tool(Hand::left, DeviceToolSettings{});
    simulation->start();
  } else {
    // A force model every 5 ms, as the simulation publishes one per cycle: a 100 N/m spring to
    // the circle's centre (1 N on the circle).
    publisher = std::thread([&] {
      while (!stop_publisher.load()) {
        LocalForceModel wall;
        wall.stiffness_n_per_m = Eigen::Matrix3d::Identity() * 100.0;
        wall.position_m = circle_centre_m;
        wall.radius_m = 0.02;
        servo->publish(wall);
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    });
  }
  servo->start();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  servo->stop();
  if (simulation) simulation->stop();
  stop_publisher = true;
  if (publisher.joinable()) publisher.join();
  if (!two) return {{condition, run, "", servo->stats()}};
  return {{condition, run, "right", servo->stats(Hand::right)},
          {condition, run, "left", servo->stats(Hand::left)}};
}

int run(const ServoBenchOptions& o) {
  std::filesystem::create_directories(o.output_dir);
  const SceneSetup scene = default_scene(o.tets);
  std::vector<ServoRun> runs;
  for (Condition condition : {Condition::alone, Condition::simulation, Condition::two_devices})
    for (int r = 0; r < o.runs; ++r)
      for (const ServoRun& one : run_once(scene, condition, r + 1, o.seconds)) {
        runs.push_back(one);
        const ServoStats& s = one.stats;
        std::cout << condition_name(condition) << (one.device.empty() ? "" : ", " + one.device)
                  << ", run " << r + 1 << ": " << number(s.rate_hz()) << " Hz, p99 "
                  << number(s.period_percentile_s(0.99) * 1e3) << " ms, max "
                  << number(s.max_period_s * 1e3) << " ms, " << s.missed_deadlines
                  << " missed deadlines" << std::endl;
      }
  std::ostringstream md;
  md << "# Haptic servo timing\n\n"
     << written_by("liversim-cli bench-servo --seconds " + number(o.seconds) + " --runs " +
                   std::to_string(o.runs) + " --tets " + std::to_string(o.tets))
     << "\n\nWall-clock timing of the servo thread on this machine: it is shared "
        "with other work, so the tails vary from run to run; the tests assert only loose sanity "
        "bounds (docs/haptics.md).\n\n"
     << "The device is a scripted trajectory: the probe's ball pressing 3 mm into the top of the "
        "liver and circling there (radius 10 mm, a turn every 2 s). **Alone**, the servo is the "
        "only busy thread: a model of a 100 N/m spring to the circle's centre (1 N on the circle) "
        "is published every 5 ms, as the simulation would. **With the simulation**, the real-time "
        "simulation of the "
     << scene.description
     << " runs on all cores with the probe as the device's tool, publishing the local force model "
        "each cycle: the workstation's load without its window. **Two devices** (issue 43): a "
        "device in each hand, each holding a probe, the left hand's circle 4 cm to the left of the "
        "right's; one servo schedule reads both and writes each its own force in the same tick, so "
        "both devices have the same periods, listed for each.\n\n"
     << "A tick is late (a missed deadline) when its period exceeds 1.5 ms. Periods come from "
        "the servo's histogram (10 µs bins), so the percentiles are bin upper edges.\n\n"
     << "| condition | device | run | ticks | rate (Hz) | period p50 (ms) | p99 (ms) | p99.9 (ms) "
        "| max (ms) | missed deadlines | watchdog trips | largest force (N) |\n"
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const ServoRun& run : runs) {
    const ServoStats& s = run.stats;
    md << "| " << condition_name(run.condition) << " | "
       << (run.device.empty() ? "the one" : run.device + " hand's") << " | " << run.run << " | "
       << s.ticks << " | " << number(s.rate_hz()) << " | "
       << number(s.period_percentile_s(0.5) * 1e3) << " | "
       << number(s.period_percentile_s(0.99) * 1e3) << " | "
       << number(s.period_percentile_s(0.999) * 1e3) << " | " << number(s.max_period_s * 1e3)
       << " | " << s.missed_deadlines << " | " << s.watchdog_trips << " | " << number(s.max_force_n)
       << " |\n";
  }
  return write_report(o.output_dir / "haptics-servo.md", md.str());
}

}  // namespace

std::function<std::optional<int>()> add_servo_bench_command(CLI::App& app) {
  auto options = std::make_shared<ServoBenchOptions>();
  auto* command = app.add_subcommand(
      "bench-servo",
      "Measure the haptic servo's rate and tick jitter alone, with the simulation running, and "
      "with a device in each hand; write docs/haptics-servo.md");
  command->add_option("--seconds", options->seconds, "Length of each run (s)")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  command->add_option("--runs", options->runs, "Runs of each condition")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  command->add_option("--tets", options->tets, "Liver size of the simulation's load")
      ->check(CLI::Range(100, 2'000'000))
      ->capture_default_str();
  command->add_option("--output-dir", options->output_dir, "Where haptics-servo.md goes")
      ->capture_default_str();
  return [options, command]() -> std::optional<int> {
    if (!command->parsed()) return std::nullopt;
    return guarded([&] { return run(*options); });
  };
}

}  // namespace liversim::cli
