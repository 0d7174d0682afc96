#include "liversim/haptics/haptics.h"
#include "liversim/engine/validation_message.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace liversim {
namespace {

constexpr double kMmPerM = 1000.0;

const auto& out_of_range = out_of_range_message;

bool finite(const DeviceForceModel& model) {
  return model.force_n.allFinite() && model.stiffness_n_per_m.allFinite() &&
         model.damping_n_s_per_m.allFinite() && model.position_mm.allFinite() &&
         model.velocity_mm_per_s.allFinite() && std::isfinite(model.radius_mm) &&
         std::isfinite(model.published_s);
}

// Scales `force` down to at most `limit` in magnitude; returns whether it did.
bool clamp_magnitude(Eigen::Vector3d& force, double limit) {
  const double magnitude = force.norm();
  if (magnitude <= limit) return false;
  force *= limit / magnitude;
  return true;
}

}  // namespace

Eigen::Vector3d WorkspaceMapping::scene_position_m(const Eigen::Vector3d& device_mm) const {
  return offset_m + scale * (rotation * (device_mm / kMmPerM));
}
Eigen::Quaterniond WorkspaceMapping::scene_orientation(const Eigen::Quaterniond& device) const {
  return (rotation * device).normalized();
}
Eigen::Vector3d WorkspaceMapping::scene_velocity_m_per_s(
    const Eigen::Vector3d& device_mm_per_s) const {
  return scale * (rotation * (device_mm_per_s / kMmPerM));
}
Eigen::Vector3d WorkspaceMapping::device_position_mm(const Eigen::Vector3d& scene_m) const {
  return kMmPerM * (rotation.conjugate() * ((scene_m - offset_m) / scale));
}
Eigen::Vector3d WorkspaceMapping::device_force_n(const Eigen::Vector3d& scene_force_n) const {
  return scale * (rotation.conjugate() * scene_force_n);
}
Eigen::Matrix3d WorkspaceMapping::device_gain(const Eigen::Matrix3d& scene_gain) const {
  const Eigen::Matrix3d r = rotation.toRotationMatrix();
  return scale * scale * (r.transpose() * scene_gain * r);
}

std::optional<std::string> validate(const WorkspaceMapping& mapping) {
  if (!std::isfinite(mapping.scale) || !(mapping.scale > 0.0))
    return out_of_range("workspace scale (scene m per device m)", mapping.scale,
                        "a finite value > 0");
  if (!mapping.rotation.coeffs().allFinite() || std::abs(mapping.rotation.norm() - 1.0) > 1e-6)
    return out_of_range("workspace rotation (quaternion norm)", mapping.rotation.norm(),
                        "a unit quaternion");
  if (!mapping.offset_m.allFinite()) return std::string("workspace offset (m) is not finite");
  return std::nullopt;
}

DeviceForceModel to_device(const LocalForceModel& model, const WorkspaceMapping& mapping) {
  DeviceForceModel out;
  out.force_n = mapping.device_force_n(model.force_n);
  out.stiffness_n_per_m = mapping.device_gain(model.stiffness_n_per_m);
  out.damping_n_s_per_m = mapping.device_gain(model.damping_n_s_per_m);
  out.position_mm = mapping.device_position_mm(model.position_m);
  out.velocity_mm_per_s =
      kMmPerM * (mapping.rotation.conjugate() * (model.velocity_m_per_s / mapping.scale));
  out.radius_mm = kMmPerM * model.radius_m / mapping.scale;
  out.published_s = model.published_s;
  return out;
}

std::optional<std::string> validate(const HapticSafetySettings& settings) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(settings.force_cap_n))
    return out_of_range("force cap (N)", settings.force_cap_n, "a finite value > 0");
  if (!positive(settings.max_force_rate_n_per_s))
    return out_of_range("force rate limit (N/s)", settings.max_force_rate_n_per_s,
                        "a finite value > 0");
  if (!positive(settings.stale_after_s))
    return out_of_range("stale model limit (s)", settings.stale_after_s, "a finite value > 0");
  if (!positive(settings.ramp_s))
    return out_of_range("force ramp (s)", settings.ramp_s, "a finite value > 0");
  if (!positive(settings.nominal_rate_hz))
    return out_of_range("servo rate (Hz)", settings.nominal_rate_hz, "a finite value > 0");
  if (!positive(settings.min_rate_hz) || settings.min_rate_hz >= settings.nominal_rate_hz)
    return out_of_range("lowest servo rate (Hz)", settings.min_rate_hz,
                        "a finite value > 0 and below the servo rate");
  return std::nullopt;
}

double ServoStats::rate_hz() const {
  const double span_s = last_tick_s - first_tick_s;
  return ticks > 1 && span_s > 0.0 ? static_cast<double>(ticks - 1) / span_s : 0.0;
}

double ServoStats::period_percentile_s(double fraction) const {
  std::uint64_t total = 0;
  for (std::uint32_t count : period_histogram) total += count;
  if (total == 0) return 0.0;
  const double wanted = fraction * static_cast<double>(total);
  std::uint64_t seen = 0;
  for (int bin = 0; bin < kBins; ++bin) {
    seen += period_histogram[bin];
    if (static_cast<double>(seen) >= wanted) return (bin + 1) * kBinS;
  }
  return kBins * kBinS;
}

HapticRenderer::HapticRenderer(const DeviceLimits& limits, const HapticSafetySettings& settings)
    : limits_(limits),
      settings_(settings),
      force_limit_n_(std::min(settings.force_cap_n, limits.max_force_n)) {}

bool HapticRenderer::clamp_gain(Eigen::Matrix3d& gain, double max) {
  const Eigen::Matrix3d symmetric = 0.5 * (gain + gain.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(symmetric);
  const Eigen::Vector3d values = eigen.eigenvalues();
  const Eigen::Vector3d clamped = values.cwiseMax(0.0).cwiseMin(max);
  const bool changed = (clamped - values).cwiseAbs().maxCoeff() > 1e-12 * std::max(1.0, max) ||
                       (gain - symmetric).cwiseAbs().maxCoeff() > 1e-12 * std::max(1.0, max);
  gain = eigen.eigenvectors() * clamped.asDiagonal() * eigen.eigenvectors().transpose();
  return changed;
}

void HapticRenderer::accept(const DeviceForceModel& model) {
  if (!finite(model) || model.radius_mm < 0.0) {
    ++stats_.rejected_models;
    return;
  }
  model_ = model;
  const bool stiff = clamp_gain(model_.stiffness_n_per_m, limits_.max_stiffness_n_per_m);
  const bool damped = clamp_gain(model_.damping_n_s_per_m, limits_.max_damping_n_s_per_m);
  if (stiff || damped) ++stats_.stiffness_clamps;
}

void HapticRenderer::hold_zero(bool zero) {
  held_ = zero;
  if (zero) restart_ramp();
}

void HapticRenderer::restart_ramp() {
  gain_ = 0.0;
  last_force_n_.setZero();
}

Eigen::Vector3d HapticRenderer::command(double now_s, const DeviceSample& sample) {
  // Tick timing: statistics and the watchdog's view of the servo rate.
  const double period_s = last_tick_s_ >= 0.0 ? now_s - last_tick_s_ : 0.0;
  if (stats_.ticks == 0) stats_.first_tick_s = now_s;
  ++stats_.ticks;
  stats_.last_tick_s = now_s;
  if (last_tick_s_ >= 0.0) {
    const int bin =
        std::clamp(static_cast<int>(period_s / ServoStats::kBinS), 0, ServoStats::kBins - 1);
    ++stats_.period_histogram[bin];
    stats_.max_period_s = std::max(stats_.max_period_s, period_s);
    if (period_s > 1.5 / settings_.nominal_rate_hz) ++stats_.missed_deadlines;
  }
  last_tick_s_ = now_s;
  const double dt_s = std::clamp(period_s, 0.0, 1.0 / settings_.min_rate_hz);

  if (!sample.position_mm.allFinite() || !sample.velocity_mm_per_s.allFinite()) {
    ++stats_.rejected_samples;
    last_force_n_.setZero();  // nowhere to push: nothing
    return last_force_n_;
  }
  if (held_) return Eigen::Vector3d::Zero();

  // The watchdog: a stale (or absent) model or a collapsed servo rate ramps the force to zero.
  const bool stale =
      model_.published_s < 0.0 || now_s - model_.published_s > settings_.stale_after_s;
  const bool slow = period_s > 1.0 / settings_.min_rate_hz;
  const bool trip = stale || slow;
  if (trip && !tripped_ && model_.published_s >= 0.0) ++stats_.watchdog_trips;
  tripped_ = trip;
  const double ramp_step = (slow ? period_s : dt_s) / settings_.ramp_s;
  gain_ = trip ? std::max(0.0, gain_ - ramp_step) : std::min(1.0, gain_ + ramp_step);

  // The model at the device, evaluated within its radius of x0.
  Eigen::Vector3d offset_mm = sample.position_mm - model_.position_mm;
  const double reach_mm = offset_mm.norm();
  if (reach_mm > model_.radius_mm) offset_mm *= model_.radius_mm / reach_mm;
  Eigen::Vector3d force =
      model_.force_n - model_.stiffness_n_per_m * (offset_mm / kMmPerM) -
      model_.damping_n_s_per_m * ((sample.velocity_mm_per_s - model_.velocity_mm_per_s) / kMmPerM);
  // The linearisation does not reverse the force it was made around: a contact only pushes.
  const double f0 = model_.force_n.norm();
  if (f0 > 0.0) {
    const Eigen::Vector3d along = model_.force_n / f0;
    const double component = force.dot(along);
    if (component < 0.0) force -= component * along;
  }
  if (clamp_magnitude(force, force_limit_n_)) ++stats_.force_clamps;
  force *= gain_;
  // Rate limit against the last commanded force.
  Eigen::Vector3d change = force - last_force_n_;
  if (clamp_magnitude(change, settings_.max_force_rate_n_per_s * std::max(dt_s, 1e-6)))
    ++stats_.rate_limited;
  force = last_force_n_ + change;
  clamp_magnitude(force, force_limit_n_);
  if (!force.allFinite()) force.setZero();  // cannot happen with finite inputs; never send a NaN
  last_force_n_ = force;
  stats_.max_force_n = std::max(stats_.max_force_n, force.norm());
  return force;
}

Eigen::Quaterniond device_axes_from_view(const Eigen::Vector3d& toward_viewer,
                                         const Eigen::Vector3d& view_up) {
  const Eigen::Vector3d z = toward_viewer.normalized();
  const Eigen::Vector3d y = (view_up - z.dot(view_up) * z).normalized();
  Eigen::Matrix3d axes;
  axes.col(0) = y.cross(z);  // right
  axes.col(1) = y;
  axes.col(2) = z;
  return Eigen::Quaterniond(axes).normalized();
}

Eigen::Vector3d opening_view_camera_offset_m() {
  return {0.05, 0.12, 0.55};
}

Eigen::Quaterniond opening_view_device_axes() {
  return device_axes_from_view(opening_view_camera_offset_m(), Eigen::Vector3d::UnitY());
}

Eigen::Vector3d device_home_m(const NodeArray& position_m, const Eigen::Quaterniond& axes) {
  Eigen::AlignedBox3d box;
  for (std::size_t n = 0; n < position_m.size(); ++n) box.extend(position_m.at(n));
  const Eigen::Vector3d toward_viewer = axes * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d half = box.sizes() / 2.0;
  double out_m = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis)
    if (std::abs(toward_viewer[axis]) > 1e-9)
      out_m = std::min(out_m, half[axis] / std::abs(toward_viewer[axis]));
  return box.center() + (out_m + 0.01) * toward_viewer;
}

WorkspaceMapping first_use_mapping(const NodeArray& position_m, const Eigen::Quaterniond& axes) {
  WorkspaceMapping mapping;
  mapping.rotation = axes;
  mapping.scale = 1.5;
  mapping.offset_m = device_home_m(position_m, axes);
  return mapping;
}

Eigen::Quaterniond tool_orientation_from_view(const Eigen::Quaterniond& axes) {
  const Eigen::Vector3d toward_viewer = axes * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d view_up = axes * Eigen::Vector3d::UnitY();
  constexpr double kTiltRad = 35.0 * std::numbers::pi / 180.0;
  const Eigen::Vector3d shaft_direction =
      (std::cos(kTiltRad) * toward_viewer + std::sin(kTiltRad) * view_up).normalized();
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), shaft_direction);
}

LocalForceModel tool_force_model(std::span<const NodeSpring> springs, const NodeArray& position_m,
                                 const Eigen::Vector3d& tool_point_m, double servo_period_s) {
  LocalForceModel model;
  model.force_n = spring_reaction_force_n(springs, position_m);
  double stiffness = 0.0;
  for (const NodeSpring& spring : springs) stiffness += spring.stiffness_n_per_m;
  model.stiffness_n_per_m = stiffness * Eigen::Matrix3d::Identity();
  model.damping_n_s_per_m = stiffness * servo_period_s * Eigen::Matrix3d::Identity();
  model.position_m = tool_point_m;
  return model;
}

Tool device_tool(const DeviceToolSettings& settings, const Eigen::Vector3d& origin_m,
                 std::uint32_t buttons, const std::optional<Eigen::Quaterniond>& stylus) {
  Tool tool;
  tool.kind = settings.kind;
  tool.geometry = settings.geometry;
  tool.pose.origin_m = origin_m;
  tool.pose.orientation = (stylus ? *stylus : settings.orientation).normalized();
  const bool acting = (buttons & settings.action_buttons) != 0;
  tool.jaw_opening = acting ? 0.0 : 1.0;
  tool.blade_armed = acting;
  return tool;
}

}  // namespace liversim
