#pragma once
// The Phantom Omni / Geomagic Touch through the vendor's OpenHaptics HD runtime, `libHD.so`. The
// runtime is proprietary and not in Debian, so it is loaded with dlopen at run time and its
// functions are looked up by name: nothing of the SDK is needed to build, and without the runtime
// the device is simply not offered.
//
// Servo path: start_own_clock() schedules a callback on the vendor's scheduler (about 1 kHz). Each
// tick it begins a device frame, captures position, velocity and buttons, calls `tick`, ends the
// frame and collects the device's errors. Inside `tick`, read() returns the captured sample and
// write_force() sets the force of the frame. Without the own clock, each read() and write_force()
// runs a device frame of its own on the caller's thread (for one-off queries and tests; a servo
// loop on the real device should use the own clock). Either way, call read() and write_force()
// from one thread at a time.
//
// Errors: warm motors, an exceeded force, force impulse or velocity limit and a force error are
// recoverable (reported once, by the next read()); anything else is fatal, sticks, and from then
// on the force is held at zero.

#include "liversim/haptics/haptic_device.h"

#include <atomic>
#include <memory>
#include <string>

namespace liversim {

struct OpenHapticsOpening {
  std::unique_ptr<HapticDevice> device;  // an OpenHapticsDevice; null when `problem` says why
  std::string problem;                   // empty on success
};

// Loads `library` (found the way dlopen finds it) once per process and never unloads it: the
// vendor driver fails when loaded a second time. Opens the named device (nullptr: the default
// device). Never throws for a missing runtime or device: `problem` says what is missing.
OpenHapticsOpening open_openhaptics_device(const std::string& library = "libHD.so",
                                           const char* device_name = nullptr);

namespace openhaptics {
struct Api;  // the runtime's functions, bound by name
}

class OpenHapticsDevice final : public HapticDevice {
 public:
  // Zeroes the force, stops the own clock if it runs and disables the device.
  ~OpenHapticsDevice() override;
  OpenHapticsDevice(const OpenHapticsDevice&) = delete;
  OpenHapticsDevice& operator=(const OpenHapticsDevice&) = delete;

  std::string name() const override { return name_; }  // HD_DEVICE_MODEL_TYPE
  DeviceLimits limits() const override { return limits_; }

  // `time_s` is unused: the device has its own clock.
  DeviceStatus read(double time_s, DeviceSample& sample) override;
  DeviceStatus write_force(const Eigen::Vector3d& force_n) override;

  // Returns false if the clock already runs or the scheduler would not start (the servo loop then
  // runs its own thread and read()/write_force() run their own frames).
  bool start_own_clock(Tick tick, void* context) override;
  void stop_own_clock() override;

  // hdCheckCalibration() == HD_CALIBRATION_OK: checked on open and on every servo tick.
  bool calibration_ok() const { return calibration_ok_.load(std::memory_order_relaxed); }

 private:
  friend OpenHapticsOpening open_openhaptics_device(const std::string&, const char*);
  OpenHapticsDevice(const openhaptics::Api& api, unsigned int device_handle, std::string name,
                    DeviceLimits limits);

  static unsigned int servo_callback(void* device);
  void servo_tick();
  void capture_sample();
  void set_force(const Eigen::Vector3d& force_n);
  void collect_errors();
  DeviceStatus take_status();
  void zero_force_in_own_frame();

  const openhaptics::Api& api_;
  const unsigned int device_handle_;
  const std::string name_;
  const DeviceLimits limits_;
  std::atomic<bool> calibration_ok_{false};

  // Set by the controlling thread while the scheduler is stopped.
  Tick tick_ = nullptr;
  void* tick_context_ = nullptr;
  unsigned long servo_handle_ = 0;
  std::atomic<bool> own_clock_running_{false};
  std::atomic<bool> zero_force_requested_{false};  // stop: the next tick writes zero, skips `tick`
  std::atomic<bool> zero_force_written_{false};

  // Servo thread (or the caller's thread without the own clock).
  DeviceSample latest_;
  DeviceStatus status_;  // the worst error since the last read(); a fatal one sticks
};

}  // namespace liversim
