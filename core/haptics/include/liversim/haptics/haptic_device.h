#pragma once
// Haptic devices behind one interface: the Phantom Omni / Geomagic Touch through the vendor's
// OpenHaptics runtime (loaded at run time), the mouse and keyboard, a scripted trajectory and the
// replay of a logged session. Device units are the vendor's: position mm, velocity mm/s, force N.
//
// The servo thread calls read() and write_force() once per tick: neither may block or allocate.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <string>

namespace liversim {

// The device's nominal limits (read from the device where it reports them).
struct DeviceLimits {
  double max_force_n = 3.3;
  double max_continuous_force_n = 0.88;
  double max_stiffness_n_per_m = 700.0;
  double max_damping_n_s_per_m = 5.0;
  double workspace_radius_mm = 100.0;
};

struct DeviceSample {
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_mm_per_s = Eigen::Vector3d::Zero();
  // Bit 0: first button (grasp / cut), bit 1: second; kRepositioned is no button.
  std::uint32_t buttons = 0;
  // The stylus's orientation in the device frame (its gimbal angles), where the device reports
  // one: the stylus frame's −z points from the hand to the stylus's tip, as a tool's working end
  // does in the tool frame (tools.h). None (the mouse, a script without it): the tool keeps the
  // direction its DeviceToolSettings set.
  std::optional<Eigen::Quaterniond> orientation;
};

// Set in a sample's buttons when the device got to its position by a jump, not a motion (the
// mouse puts the tool down where it presses): path metrics count no distance to it.
inline constexpr std::uint32_t kRepositioned = 1u << 31;

enum class DeviceFault {
  none,
  recoverable,  // e.g. warm motors, a force or velocity limit exceeded: go on, force ramps back
  fatal,        // the device is gone or broken: force output stops
};

// What went wrong on the servo path. `message` points to static storage (no allocation).
struct DeviceStatus {
  DeviceFault fault = DeviceFault::none;
  const char* message = "";
  bool ok() const { return fault == DeviceFault::none; }
};

class HapticDevice {
 public:
  virtual ~HapticDevice() = default;

  virtual std::string name() const = 0;
  virtual DeviceLimits limits() const = 0;

  // Servo thread. `time_s` is the servo clock (seconds since the servo started): scripted and
  // replay devices play their trajectory on it.
  virtual DeviceStatus read(double time_s, DeviceSample& sample) = 0;
  virtual DeviceStatus write_force(const Eigen::Vector3d& force_n) = 0;

  // Devices with their own servo scheduler (OpenHaptics) call `tick` at their rate from their
  // thread; the others return false and the servo loop runs its own 1 kHz thread.
  using Tick = void (*)(void* context);
  virtual bool start_own_clock(Tick /*tick*/, void* /*context*/) { return false; }
  virtual void stop_own_clock() {}
};

}  // namespace liversim
