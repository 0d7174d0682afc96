#pragma once
// The haptic force path's mathematics: the workspace mapping (device mm → scene m), the local
// force model the simulation publishes each step, and the renderer the servo thread runs at 1 kHz
// to turn that model into a safe force for the device.
//
// The simulation is slower than the servo, so it publishes a linearisation of the force on the
// tool around where the tool was, F = F0 − K·(x − x0) − D·(v − v0), valid within a radius of x0
// (OpenSurgSim's VirtualToolCoupler and VRPN force fields do the same). The renderer evaluates it
// at the device's position every tick and makes it safe: K and D clamped to the device's nominal
// maxima (symmetric, no negative eigenvalues: an active spring is unsafe), |F| clamped to a
// configured cap and the device's maximum, dF per tick rate-limited, and a watchdog that ramps the
// force to zero when the model is stale or the servo rate collapses.

#include "liversim/engine/forces.h"
#include "liversim/haptics/haptic_device.h"
#include "liversim/interaction/tools.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace liversim {

// Device → scene: x_scene = offset + scale · R · x_device (device positions in mm, scene in m).
// The coupling is energy-consistent: the power the hand puts in equals the power the tool puts in,
// so forces scale by `scale` and stiffnesses by scale² on their way back (passivity is kept).
struct WorkspaceMapping {
  double scale = 1.0;  // scene metres per device metre
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();

  Eigen::Vector3d scene_position_m(const Eigen::Vector3d& device_mm) const;
  // The stylus's orientation in the scene: turned by the same rotation as positions (a uniform
  // scale does not turn anything).
  Eigen::Quaterniond scene_orientation(const Eigen::Quaterniond& device) const;
  Eigen::Vector3d scene_velocity_m_per_s(const Eigen::Vector3d& device_mm_per_s) const;
  Eigen::Vector3d device_position_mm(const Eigen::Vector3d& scene_m) const;
  Eigen::Vector3d device_force_n(const Eigen::Vector3d& scene_force_n) const;
  // For stiffness (N/m) and damping (N·s/m) alike: scale² · Rᵀ·M·R.
  Eigen::Matrix3d device_gain(const Eigen::Matrix3d& scene_gain) const;
};

// The problem with the mapping, if any (naming the field, its value and what is expected).
std::optional<std::string> validate(const WorkspaceMapping& mapping);

// A device not calibrated yet is set up from the view of the scene: the workstation's camera, or
// for a headless recording (liversim-cli record) the workstation's opening view.
// The device's axes in the scene: x to the right of the view, y up, z toward the viewer.
// `toward_viewer` points from the scene to the camera; `view_up` is the camera's up (made
// orthogonal to it here).
Eigen::Quaterniond device_axes_from_view(const Eigen::Vector3d& toward_viewer,
                                         const Eigen::Vector3d& view_up);
// The workstation's opening view (LiverScene::reset_camera looks from here at the organ's centre,
// y up): from the front, slightly from above and the left.
Eigen::Vector3d opening_view_camera_offset_m();
// The device's axes in that view.
Eigen::Quaterniond opening_view_device_axes();
// Where such a device's origin goes: from the organ's centre (the box of `position_m`) toward the
// viewer (the axes' z), out of the box and a centimetre further, just in front of the organ.
Eigen::Vector3d device_home_m(const NodeArray& position_m, const Eigen::Quaterniond& axes);
// The mapping of a device at its first use: its axes the view's, its origin at device_home_m, and
// its workspace (about 16 cm across for an Omni) over the liver's 25 cm (scale 1.5).
WorkspaceMapping first_use_mapping(const NodeArray& position_m, const Eigen::Quaterniond& axes);
// How a tool is held in that view: its shaft toward the viewer, tilted up by 35° (as a
// laparoscopic instrument comes in through a port, and so that it shows).
Eigen::Quaterniond tool_orientation_from_view(const Eigen::Quaterniond& axes);

// The force on the tool near where it was, in the scene frame (SI units).
struct LocalForceModel {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();  // F0: at x0 moving at v0
  Eigen::Matrix3d stiffness_n_per_m = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d damping_n_s_per_m = Eigen::Matrix3d::Zero();
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();        // x0
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();  // v0
  double radius_m = 0.002;   // beyond it the model is evaluated at the nearest point within
  double published_s = 0.0;  // on the servo clock: when the simulation made it
};

// The same model in the device's frame and units (mm for positions; N, N/m, N·s/m for the rest),
// as the servo evaluates it.
struct DeviceForceModel {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  Eigen::Matrix3d stiffness_n_per_m = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d damping_n_s_per_m = Eigen::Matrix3d::Zero();
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_mm_per_s = Eigen::Vector3d::Zero();
  double radius_mm = 0.0;
  double published_s = -1.0;  // < 0: never published (no force)
};

DeviceForceModel to_device(const LocalForceModel& model, const WorkspaceMapping& mapping);

struct HapticSafetySettings {
  double force_cap_n = 2.5;               // never more, whatever the device allows
  double max_force_rate_n_per_s = 300.0;  // |dF/dt| limit: no jolts
  double stale_after_s = 0.1;             // a model older than this is not trusted
  double ramp_s = 0.05;                   // the watchdog's ramp to zero (and back)
  double nominal_rate_hz = 1000.0;        // the servo's intended rate
  double min_rate_hz = 250.0;             // a tick period longer than 1 / this trips the watchdog
};

std::optional<std::string> validate(const HapticSafetySettings& settings);

// What the servo did, kept by the renderer without allocating. Tick periods go into a histogram
// of 10 µs bins up to 20 ms (longer ones in the last bin).
struct ServoStats {
  static constexpr int kBins = 2000;
  static constexpr double kBinS = 10e-6;

  std::uint64_t ticks = 0;
  std::uint64_t missed_deadlines = 0;  // ticks later than 1.5 nominal periods
  std::uint64_t stiffness_clamps = 0;  // models whose K or D exceeded the device's maxima
  std::uint64_t force_clamps = 0;      // ticks whose |F| was cut to the cap
  std::uint64_t rate_limited = 0;      // ticks whose dF was cut
  std::uint64_t watchdog_trips = 0;    // times the watchdog began a ramp to zero
  std::uint64_t rejected_models = 0;   // models with a NaN or infinity
  std::uint64_t rejected_samples = 0;  // device samples with a NaN or infinity
  std::uint64_t device_faults = 0;
  double first_tick_s = 0.0, last_tick_s = 0.0;
  double max_period_s = 0.0;
  double max_force_n = 0.0;  // largest |F| commanded
  std::array<std::uint32_t, kBins> period_histogram{};

  double rate_hz() const;  // mean over the ticks counted
  // The period below which `fraction` of the tick periods fell (bin upper edge), s.
  double period_percentile_s(double fraction) const;
};

// Turns the newest force model into the force for the device, tick by tick. Used by the servo
// thread only (or by tests with a made-up clock); allocates nothing.
class HapticRenderer {
 public:
  HapticRenderer(const DeviceLimits& limits, const HapticSafetySettings& settings);

  // A new model from the simulation: clamped here, once, not every tick. A model with a NaN or
  // infinity is refused (the previous one stands, and goes stale).
  void accept(const DeviceForceModel& model);

  // The force to command at servo time `now_s` for the device's `sample`.
  Eigen::Vector3d command(double now_s, const DeviceSample& sample);

  // Pause, error or shutdown: the force is zero from the next tick on, and ramps back up after.
  void hold_zero(bool zero);
  // A passing fault (e.g. warm motors): the force drops to zero now and ramps back up.
  void restart_ramp();

  // The watchdog's gain now: 1 in normal running, ramping to 0 when tripped.
  double gain() const { return gain_; }
  bool watchdog_tripped() const { return tripped_; }
  const ServoStats& stats() const { return stats_; }
  const DeviceForceModel& model() const { return model_; }

  // Clamps the symmetric part of `gain` to eigenvalues in [0, max]; returns whether it changed it.
  static bool clamp_gain(Eigen::Matrix3d& gain, double max);

 private:
  DeviceLimits limits_;
  HapticSafetySettings settings_;
  double force_limit_n_;
  DeviceForceModel model_;
  Eigen::Vector3d last_force_n_ = Eigen::Vector3d::Zero();
  double last_tick_s_ = -1.0;
  double gain_ = 0.0;  // starts at zero and ramps up: no jolt on the first model
  bool tripped_ = false;
  bool held_ = false;
  ServoStats stats_;
};

// The local model of the force on a tool that holds and pushes the tissue through `springs`
// (anchored on the tool) with nodes at `position`: F0 their reaction, K the sum of their
// stiffnesses (the springs alone, stiffer than with the tissue behind them; the renderer clamps K
// to the device's maximum), and the damping K·T that keeps the sampled coupling passive
// (Colgate: b > K·T/2, T the servo period). x0 is the tool's point.
LocalForceModel tool_force_model(std::span<const NodeSpring> springs, const NodeArray& position_m,
                                 const Eigen::Vector3d& tool_point_m, double servo_period_s);

// How a haptic device holds a tool. The device's point, through the workspace mapping, is the
// tool's origin: the probe's ball centre, the forceps' jaw hinge, the blade's heel. Where the
// device reports the stylus's orientation (the Omni's gimbal angles, a script that gives it), the
// tool is turned with the stylus (its shaft along the stylus, the working end at the stylus's
// tip); otherwise its shaft keeps `orientation`.
struct DeviceToolSettings {
  ToolKind kind = ToolKind::probe;
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // tool frame → scene
  // The device buttons (bit mask) that act: held, the forceps close and the scalpel's blade is
  // armed to cut.
  std::uint32_t action_buttons = 1;
  ToolGeometry geometry;
};

// The tool at scene point `origin_m` with the device's `buttons` down; turned as the stylus is in
// the scene (`stylus`, WorkspaceMapping::scene_orientation), or, without it, by the settings.
Tool device_tool(const DeviceToolSettings& settings, const Eigen::Vector3d& origin_m,
                 std::uint32_t buttons,
                 const std::optional<Eigen::Quaterniond>& stylus = std::nullopt);

}  // namespace liversim
