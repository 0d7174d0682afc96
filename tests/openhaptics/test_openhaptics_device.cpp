// The OpenHaptics driver against fake_hd.cpp, a libHD.so of our own that emulates a PHANTOM Omni:
// loading and its failures, the device's limits and units, the servo tick on the vendor's
// scheduler, error classes, and shutdown.
#include "liversim/haptics/openhaptics_device.h"
#include "liversim/haptics/servo_loop.h"

#include <dlfcn.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace liversim {
namespace {

const char* const kFakeRuntime = LIVERSIM_FAKE_HD_LIBRARY;

// The fake's stylus path: a 20 mm circle about (0, 0, -20) mm in z = -20 mm, one turn in 2 s.
const Eigen::Vector3d kCentreMm(0.0, 0.0, -20.0);
constexpr double kRadiusMm = 20.0;
constexpr double kTurnRadPerS = 3.14159265358979323846;

// The fake's test hooks. Once the driver has loaded the fake, the test only borrows it (dlopen with
// RTLD_NOLOAD, then dlclose) so that it holds no reference that would hide an unload; before that,
// the test loads it itself and keeps it.
namespace fake {

template <typename Function>
Function hook(const char* name) {
  void* library = dlopen(kFakeRuntime, RTLD_NOW | RTLD_NOLOAD);
  const bool borrowed = library != nullptr;
  if (!borrowed) library = dlopen(kFakeRuntime, RTLD_NOW | RTLD_GLOBAL);
  if (library == nullptr) throw std::runtime_error(std::string("cannot load ") + kFakeRuntime);
  auto function = reinterpret_cast<Function>(dlsym(library, name));
  if (borrowed) dlclose(library);
  if (function == nullptr) throw std::runtime_error(std::string("the fake lacks ") + name);
  return function;
}

bool loaded() {
  void* library = dlopen(kFakeRuntime, RTLD_NOW | RTLD_NOLOAD);
  if (library != nullptr) dlclose(library);
  return library != nullptr;
}
void reset() {
  hook<void (*)()>("fake_hd_reset")();
}
void fail_init(unsigned code, int internal_code) {
  hook<void (*)(unsigned, int)>("fake_hd_fail_init")(code, internal_code);
}
void set_model(const char* name, double max_force_n, double max_continuous_force_n,
               double max_stiffness_n_per_mm, double max_damping_n_s_per_mm) {
  hook<void (*)(const char*, double, double, double, double)>("fake_hd_set_model")(
      name, max_force_n, max_continuous_force_n, max_stiffness_n_per_mm, max_damping_n_s_per_mm);
}
void set_calibration(unsigned status) {
  hook<void (*)(unsigned)>("fake_hd_set_calibration")(status);
}
void set_buttons(int buttons) {
  hook<void (*)(int)>("fake_hd_set_buttons")(buttons);
}
void set_stylus_rotation(const Eigen::Matrix3d& rotation) {
  const double column_major[9] = {rotation(0, 0), rotation(1, 0), rotation(2, 0),
                                  rotation(0, 1), rotation(1, 1), rotation(2, 1),
                                  rotation(0, 2), rotation(1, 2), rotation(2, 2)};
  hook<void (*)(const double*)>("fake_hd_set_stylus_rotation")(column_major);
}
void inject_error(unsigned code, int internal_code) {
  hook<void (*)(unsigned, int)>("fake_hd_inject_error")(code, internal_code);
}
Eigen::Vector3d last_force_n() {
  double force_n[3];
  hook<void (*)(double*)>("fake_hd_last_force")(force_n);
  return {force_n[0], force_n[1], force_n[2]};
}
// A second Omni configured under `name`, its circle 60 mm along −x from the first's.
void configure_second_device(const char* name) {
  hook<void (*)(const char*)>("fake_hd_configure_second_device")(name);
}
const Eigen::Vector3d kSecondCentreMm(-60.0, 0.0, -20.0);
// Device `handle`: 1 the default device, 2 the second.
Eigen::Vector3d last_force_n_of(unsigned handle) {
  double force_n[3];
  hook<void (*)(unsigned, double*)>("fake_hd_last_force_of")(handle, force_n);
  return {force_n[0], force_n[1], force_n[2]};
}
bool device_enabled_of(unsigned handle) {
  return hook<int (*)(unsigned)>("fake_hd_device_enabled_of")(handle) != 0;
}
bool scheduler_running() {
  return hook<int (*)()>("fake_hd_scheduler_running")() != 0;
}
int scheduled_callbacks() {
  return hook<int (*)()>("fake_hd_scheduled_callbacks")();
}
unsigned short last_priority() {
  return hook<unsigned short (*)()>("fake_hd_last_priority")();
}
bool device_enabled() {
  return hook<int (*)()>("fake_hd_device_enabled")() != 0;
}
bool force_output_enabled() {
  return hook<int (*)()>("fake_hd_force_output_enabled")() != 0;
}
int init_calls() {
  return hook<int (*)()>("fake_hd_init_calls")();
}

}  // namespace fake

bool wait_until(const std::function<bool()>& done) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!done()) {
    if (std::chrono::steady_clock::now() > give_up) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// What the servo tick saw: it runs on the fake's scheduler thread, reads, then writes `force_n`.
struct ServoProbe {
  explicit ServoProbe(HapticDevice& servo_device) : device(&servo_device) {}

  HapticDevice* device;
  std::mutex mutex;
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  std::vector<DeviceSample> samples;
  std::vector<DeviceStatus> read_statuses;
  std::vector<DeviceStatus> write_statuses;

  static void tick(void* context) {
    auto& probe = *static_cast<ServoProbe*>(context);
    const std::lock_guard lock(probe.mutex);
    DeviceSample sample;
    probe.read_statuses.push_back(probe.device->read(0.0, sample));
    probe.samples.push_back(sample);
    probe.write_statuses.push_back(probe.device->write_force(probe.force_n));
  }

  std::size_t ticks() {
    const std::lock_guard lock(mutex);
    return samples.size();
  }
  void set_force(const Eigen::Vector3d& force) {
    const std::lock_guard lock(mutex);
    force_n = force;
  }
  // Starts the device's own clock with a tick that writes `force`; true once it reaches the fake.
  bool start(const Eigen::Vector3d& force) {
    set_force(force);
    return device->start_own_clock(&tick, this) &&
           wait_until([&] { return fake::last_force_n() == force; });
  }
  bool wait_ticks(std::size_t count) {
    const std::size_t until = ticks() + count;
    return wait_until([&] { return ticks() >= until; });
  }
};

void expect_on_path(const DeviceSample& sample) {
  const Eigen::Vector3d from_centre_mm = sample.position_mm - kCentreMm;
  EXPECT_NEAR(from_centre_mm.norm(), kRadiusMm, 1e-9);
  EXPECT_NEAR(from_centre_mm.z(), 0.0, 1e-12);
  const Eigen::Vector3d expected_velocity_mm_per_s =
      kTurnRadPerS * Eigen::Vector3d::UnitZ().cross(from_centre_mm);
  EXPECT_LT((sample.velocity_mm_per_s - expected_velocity_mm_per_s).norm(), 1e-9);
  EXPECT_NEAR(sample.velocity_mm_per_s.norm(), kRadiusMm * kTurnRadPerS, 1e-9);  // 62.8 mm/s
}

TEST(OpenHapticsLoading, AbsentRuntimeIsAProblemNotACrash) {
  const OpenHapticsOpening opening = open_openhaptics_device("/nonexistent/liversim/libHD.so");
  EXPECT_EQ(opening.device, nullptr);
  EXPECT_NE(opening.problem.find("libHD.so"), std::string::npos) << opening.problem;
  EXPECT_NE(opening.problem.find("could not be loaded"), std::string::npos) << opening.problem;
  EXPECT_NE(opening.problem.find("the mouse, scripted and replay devices are still available"),
            std::string::npos)
      << opening.problem;
}

TEST(OpenHapticsLoading, LibraryWithoutTheHdApiNamesTheMissingFunction) {
  const OpenHapticsOpening opening = open_openhaptics_device("libm.so.6");
  EXPECT_EQ(opening.device, nullptr);
  EXPECT_NE(opening.problem.find("libm.so.6 lacks the function hdInitDevice"), std::string::npos)
      << opening.problem;
  EXPECT_NE(opening.problem.find("mouse, scripted and replay"), std::string::npos)
      << opening.problem;
}

class OpenHapticsFake : public ::testing::Test {
 protected:
  void SetUp() override {
    if (fake::loaded()) fake::reset();  // a fake never loaded is fresh
  }

  static std::unique_ptr<HapticDevice> open(const char* device_name = nullptr) {
    OpenHapticsOpening opening = open_openhaptics_device(kFakeRuntime, device_name);
    EXPECT_EQ(opening.problem, "");
    return std::move(opening.device);
  }
};

TEST_F(OpenHapticsFake, InitFailureGivesTheErrorCodeInHex) {
  fake::fail_init(0x0302, 17);  // HD_COMM_ERROR
  const OpenHapticsOpening failed = open_openhaptics_device(kFakeRuntime);
  EXPECT_EQ(failed.device, nullptr);
  for (const char* part :
       {"could not open the default device", "hdInitDevice failed", "0x0302 (HD_COMM_ERROR)",
        "internal code 17", "mouse, scripted and replay"})
    EXPECT_NE(failed.problem.find(part), std::string::npos) << part << " in: " << failed.problem;
  EXPECT_FALSE(fake::device_enabled());

  fake::fail_init(0, 0);  // the device is back: the failure was not remembered
  EXPECT_NE(open(), nullptr);
}

TEST_F(OpenHapticsFake, NamedDeviceReachesTheRuntime) {
  EXPECT_NE(open("Default Device"), nullptr);
  const OpenHapticsOpening failed = open_openhaptics_device(kFakeRuntime, "Phantom2");
  EXPECT_EQ(failed.device, nullptr);
  EXPECT_NE(failed.problem.find("the device \"Phantom2\""), std::string::npos) << failed.problem;
  EXPECT_NE(failed.problem.find("0x0300 (HD_DEVICE_FAULT)"), std::string::npos) << failed.problem;
}

void expect_force_limits(const DeviceLimits& limits, double max_force_n,
                         double max_continuous_force_n, double max_stiffness_n_per_m,
                         double max_damping_n_s_per_m) {
  EXPECT_DOUBLE_EQ(limits.max_force_n, max_force_n);
  EXPECT_DOUBLE_EQ(limits.max_continuous_force_n, max_continuous_force_n);
  EXPECT_DOUBLE_EQ(limits.max_stiffness_n_per_m, max_stiffness_n_per_m);
  EXPECT_DOUBLE_EQ(limits.max_damping_n_s_per_m, max_damping_n_s_per_m);
}

TEST_F(OpenHapticsFake, LimitsAndNameAreTheDevicesInSiUnits) {
  {
    const auto omni = open();
    ASSERT_NE(omni, nullptr);
    EXPECT_EQ(omni->name(), "PHANTOM Omni");
    // The fake reports 0.7 N/mm and 0.005 N·s/mm, as OpenHaptics does.
    expect_force_limits(omni->limits(), 3.3, 0.88, 700.0, 5.0);
    // Half the diagonal of the usable 160 x 120 x 70 mm box.
    EXPECT_NEAR(omni->limits().workspace_radius_mm,
                std::sqrt(80.0 * 80.0 + 60.0 * 60.0 + 35.0 * 35.0), 1e-9);
  }
  // Values unlike DeviceLimits' defaults: they must come from the device.
  fake::set_model("Test arm", 2.5, 0.6, 0.35, 0.0025);
  const auto arm = open();
  ASSERT_NE(arm, nullptr);
  EXPECT_EQ(arm->name(), "Test arm");
  expect_force_limits(arm->limits(), 2.5, 0.6, 350.0, 2.5);
}

TEST_F(OpenHapticsFake, CalibrationIsCheckedOnOpenAndEveryTick) {
  {
    auto device = open();
    ASSERT_NE(device, nullptr);
    auto& omni = dynamic_cast<OpenHapticsDevice&>(*device);
    EXPECT_TRUE(omni.calibration_ok());
    ServoProbe probe(*device);
    ASSERT_TRUE(probe.start(Eigen::Vector3d::Zero()));
    fake::set_calibration(0x5001);  // HD_CALIBRATION_NEEDS_UPDATE
    EXPECT_TRUE(wait_until([&] { return !omni.calibration_ok(); }));
    device->stop_own_clock();
  }
  fake::set_calibration(0x5002);  // HD_CALIBRATION_NEEDS_MANUAL_INPUT
  const auto device = open();
  ASSERT_NE(device, nullptr);
  EXPECT_FALSE(dynamic_cast<OpenHapticsDevice&>(*device).calibration_ok());
}

TEST_F(OpenHapticsFake, ServoTickReadsThePathInMillimetres) {
  const auto device = open();
  ASSERT_NE(device, nullptr);
  fake::set_buttons(0b10);
  ServoProbe probe(*device);
  ASSERT_TRUE(probe.start(Eigen::Vector3d::Zero()));
  EXPECT_TRUE(fake::scheduler_running());
  EXPECT_EQ(fake::scheduled_callbacks(), 1);
  EXPECT_EQ(fake::last_priority(), 65535);  // HD_MAX_SCHEDULER_PRIORITY
  EXPECT_TRUE(probe.wait_ticks(100));
  device->stop_own_clock();

  ASSERT_GE(probe.samples.size(), 100u);
  for (std::size_t i = 0; i < probe.samples.size(); ++i) {
    SCOPED_TRACE(i);
    expect_on_path(probe.samples[i]);
    EXPECT_EQ(probe.samples[i].buttons, 0b10u);
    EXPECT_TRUE(probe.read_statuses[i].ok()) << probe.read_statuses[i].message;
  }
  // 100 ticks at about 1 kHz move the stylus some millimetres along the circle.
  EXPECT_GT((probe.samples.back().position_mm - probe.samples.front().position_mm).norm(), 1.0);
}

TEST_F(OpenHapticsFake, ForceWrittenInTheTickReachesTheDeviceInNewtons) {
  const auto device = open();
  ASSERT_NE(device, nullptr);
  EXPECT_TRUE(fake::force_output_enabled());  // else the fake applies no force
  ServoProbe probe(*device);
  const Eigen::Vector3d force_n(0.5, -1.0, 1.5);
  ASSERT_TRUE(probe.start(force_n)) << fake::last_force_n().transpose();
  device->stop_own_clock();
  for (const DeviceStatus& status : probe.write_statuses) EXPECT_TRUE(status.ok());
}

TEST_F(OpenHapticsFake, ForceErrorsAreRecoverableAndReportedOnce) {
  const auto device = open();
  ASSERT_NE(device, nullptr);
  ServoProbe probe(*device);
  const Eigen::Vector3d force_n(0.0, 0.3, 0.0);
  ASSERT_TRUE(probe.start(force_n));
  const std::pair<unsigned, const char*> recoverable[] = {{0x0200, "HD_WARM_MOTORS"},
                                                          {0x0201, "HD_EXCEEDED_MAX_FORCE"},
                                                          {0x0202, "HD_EXCEEDED_MAX_FORCE_IMPULSE"},
                                                          {0x0203, "HD_EXCEEDED_MAX_VELOCITY"},
                                                          {0x0204, "HD_FORCE_ERROR"}};
  for (const auto& [code, name] : recoverable) {
    SCOPED_TRACE(name);
    {
      const std::lock_guard lock(probe.mutex);
      probe.read_statuses.clear();
    }
    fake::inject_error(code, 3);
    const auto reported = [&] {
      const std::lock_guard lock(probe.mutex);
      for (const DeviceStatus& status : probe.read_statuses)
        if (!status.ok()) return status;
      return DeviceStatus{};
    };
    ASSERT_TRUE(wait_until([&] { return !reported().ok(); }));
    EXPECT_EQ(reported().fault, DeviceFault::recoverable);
    EXPECT_NE(std::string(reported().message).find(name), std::string::npos) << reported().message;
    // Once: the next ticks are fine again and the force still reaches the device.
    EXPECT_TRUE(probe.wait_ticks(5));
    {
      const std::lock_guard lock(probe.mutex);
      EXPECT_TRUE(probe.read_statuses.back().ok()) << probe.read_statuses.back().message;
      EXPECT_TRUE(probe.write_statuses.back().ok()) << probe.write_statuses.back().message;
    }
    EXPECT_EQ(fake::last_force_n(), force_n);
  }
  device->stop_own_clock();
}

TEST_F(OpenHapticsFake, OtherErrorsAreFatalAndStopTheForce) {
  const std::pair<unsigned, const char*> fatal[] = {
      {0x0300, "HD_DEVICE_FAULT"}, {0x0302, "HD_COMM_ERROR"}, {0x0402, "HD_FRAME_ERROR"}};
  for (const auto& [code, name] : fatal) {
    SCOPED_TRACE(name);
    const auto device = open();
    ASSERT_NE(device, nullptr);
    ServoProbe probe(*device);
    const Eigen::Vector3d force_n(1.0, 0.0, 0.0);
    ASSERT_TRUE(probe.start(force_n)) << fake::last_force_n().transpose();
    fake::inject_error(code, -2);
    const auto last_read = [&] {
      const std::lock_guard lock(probe.mutex);
      return probe.read_statuses.back();
    };
    ASSERT_TRUE(wait_until([&] { return !last_read().ok(); }));
    EXPECT_EQ(last_read().fault, DeviceFault::fatal);
    EXPECT_NE(std::string(last_read().message).find(name), std::string::npos);
    // It sticks, write_force says so, and the device gets zero whatever the tick asks for.
    EXPECT_TRUE(probe.wait_ticks(5));
    EXPECT_EQ(last_read().fault, DeviceFault::fatal);
    {
      const std::lock_guard lock(probe.mutex);
      EXPECT_EQ(probe.write_statuses.back().fault, DeviceFault::fatal);
    }
    EXPECT_EQ(fake::last_force_n(), Eigen::Vector3d::Zero());
    device->stop_own_clock();
  }
}

TEST_F(OpenHapticsFake, StopZeroesTheForceAndStopsTheScheduler) {
  auto device = open();
  ASSERT_NE(device, nullptr);
  ServoProbe probe(*device);
  const Eigen::Vector3d force_n(0.0, 2.0, 0.0);
  ASSERT_TRUE(probe.start(force_n)) << fake::last_force_n().transpose();

  device->stop_own_clock();
  EXPECT_EQ(fake::last_force_n(), Eigen::Vector3d::Zero());
  EXPECT_FALSE(fake::scheduler_running());
  EXPECT_EQ(fake::scheduled_callbacks(), 0);
  const std::size_t ticks = probe.ticks();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(probe.ticks(), ticks);  // no tick after stop
  EXPECT_TRUE(fake::device_enabled());

  // The clock starts again, and the destructor disables the device.
  ASSERT_TRUE(probe.start(force_n));
  device->stop_own_clock();
  device.reset();
  EXPECT_FALSE(fake::device_enabled());
}

TEST_F(OpenHapticsFake, DestroyingARunningDeviceStopsItFirst) {
  auto device = open();
  ASSERT_NE(device, nullptr);
  ServoProbe probe(*device);
  const Eigen::Vector3d force_n(-0.7, 0.0, 0.2);
  ASSERT_TRUE(probe.start(force_n)) << fake::last_force_n().transpose();
  device.reset();
  EXPECT_EQ(fake::last_force_n(), Eigen::Vector3d::Zero());
  EXPECT_FALSE(fake::scheduler_running());
  EXPECT_EQ(fake::scheduled_callbacks(), 0);
  EXPECT_FALSE(fake::device_enabled());
}

TEST_F(OpenHapticsFake, WithoutTheOwnClockReadAndWriteRunTheirOwnFrames) {
  const auto device = open();
  ASSERT_NE(device, nullptr);
  DeviceSample sample;
  EXPECT_TRUE(device->read(0.0, sample).ok());
  expect_on_path(sample);
  const Eigen::Vector3d force_n(0.1, 0.2, 0.3);
  EXPECT_TRUE(device->write_force(force_n).ok());
  EXPECT_EQ(fake::last_force_n(), force_n);
  // A non-finite force never reaches the motors.
  const DeviceStatus refused = device->write_force(Eigen::Vector3d(NAN, 0.0, 0.0));
  EXPECT_EQ(refused.fault, DeviceFault::recoverable);
  EXPECT_EQ(fake::last_force_n(), Eigen::Vector3d::Zero());
}

// The stylus's orientation (issue 43, item 2): the rotation of the end effector's transform
// (HD_CURRENT_TRANSFORM, column-major) is the sample's orientation; at home, none turned.
TEST_F(OpenHapticsFake, TheStylusOrientationIsReadFromTheDevicesTransform) {
  const auto device = open();
  ASSERT_NE(device, nullptr);
  DeviceSample sample;
  ASSERT_TRUE(device->read(0.0, sample).ok());
  ASSERT_TRUE(sample.orientation) << "no orientation read";
  EXPECT_LT(sample.orientation->angularDistance(Eigen::Quaterniond::Identity()), 1e-12);
  const Eigen::Quaterniond turned(
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, -1.0, 0.4).normalized()));
  fake::set_stylus_rotation(turned.toRotationMatrix());
  ASSERT_TRUE(device->read(0.001, sample).ok());
  ASSERT_TRUE(sample.orientation);
  EXPECT_LT(sample.orientation->angularDistance(turned), 1e-12);
  // Where the stylus points: its −z, turned.
  EXPECT_LT(((*sample.orientation * -Eigen::Vector3d::UnitZ()) -
             turned.toRotationMatrix() * -Eigen::Vector3d::UnitZ())
                .norm(),
            1e-12);
}

TEST_F(OpenHapticsFake, OpensTwiceInOneProcessAndTheRuntimeStaysLoaded) {
  auto first = open();
  ASSERT_NE(first, nullptr);
  const int init_calls = fake::init_calls();
  first.reset();
  EXPECT_TRUE(fake::loaded());  // the driver still holds it (run alone, the test holds none)

  const auto second = open();
  ASSERT_NE(second, nullptr);
  EXPECT_EQ(fake::init_calls(), init_calls + 1);  // the same runtime, not a fresh copy
  DeviceSample sample;
  EXPECT_TRUE(second->read(0.0, sample).ok());
  expect_on_path(sample);
}

TEST_F(OpenHapticsFake, TheServoLoopRunsOnTheVendorsSchedulerAndLeavesZeroForce) {
  const auto device = open();
  ASSERT_NE(device, nullptr);
  ServoLoop servo(*device, {});
  servo.start();
  // The simulation's push reaches the device once the start-up ramp (50 ms) is over.
  LocalForceModel push;
  push.force_n = {0.0, 0.0, 1.0};
  const bool pushed = wait_until([&] {
    servo.publish(push);
    return (fake::last_force_n() - push.force_n).norm() < 1e-9;
  });
  EXPECT_TRUE(pushed) << fake::last_force_n().transpose();
  ServoFrame frame;
  ASSERT_TRUE(servo.newest_frame(frame));
  EXPECT_NEAR(std::hypot(frame.sample.position_mm.x(), frame.sample.position_mm.y()), 20.0, 1e-6)
      << "not the fake's 20 mm circle";
  servo.stop();
  EXPECT_EQ(fake::last_force_n(), Eigen::Vector3d::Zero()) << "force left on after stop";
  EXPECT_FALSE(fake::scheduler_running());
}

// Two Omnis (issue 43, item 1): each opened by its Touch Setup name, one schedule of the vendor's
// drives both in each tick, and each device gets the force published for its own hand and reads
// its own stylus; a configuration opened twice is refused by name.
TEST_F(OpenHapticsFake, TwoOmnisByTheirConfiguredNamesAreDrivenInOneTickEachWithItsOwnForce) {
  fake::configure_second_device("Left Device");
  const auto right = open();
  const auto left = open("Left Device");
  ASSERT_NE(right, nullptr);
  ASSERT_NE(left, nullptr);
  EXPECT_TRUE(fake::device_enabled_of(1));
  EXPECT_TRUE(fake::device_enabled_of(2));
  const OpenHapticsOpening again = open_openhaptics_device(kFakeRuntime, "Left Device");
  EXPECT_EQ(again.device, nullptr);
  EXPECT_NE(again.problem.find("the device \"Left Device\""), std::string::npos) << again.problem;
  EXPECT_NE(again.problem.find("HD_DEVICE_ALREADY_INITIATED"), std::string::npos) << again.problem;
  {
    ServoLoop servo(*right, *left, {});
    servo.start();
    EXPECT_EQ(fake::scheduled_callbacks(), 1) << "one schedule for both devices";
    LocalForceModel right_push, left_push;
    right_push.force_n = {0.0, 0.0, 1.0};
    left_push.force_n = {-0.5, 0.25, 0.0};
    const bool pushed = wait_until([&] {
      servo.publish(Hand::right, right_push);
      servo.publish(Hand::left, left_push);
      return (fake::last_force_n_of(1) - right_push.force_n).norm() < 1e-9 &&
             (fake::last_force_n_of(2) - left_push.force_n).norm() < 1e-9;
    });
    EXPECT_TRUE(pushed) << fake::last_force_n_of(1).transpose() << " / "
                        << fake::last_force_n_of(2).transpose();
    ServoFrame right_frame, left_frame;
    ASSERT_TRUE(servo.newest_frame(Hand::right, right_frame));
    ASSERT_TRUE(servo.newest_frame(Hand::left, left_frame));
    EXPECT_NEAR((right_frame.sample.position_mm - kCentreMm).norm(), kRadiusMm, 1e-6)
        << "the right hand's frame is not on the first device's circle";
    EXPECT_NEAR((left_frame.sample.position_mm - fake::kSecondCentreMm).norm(), kRadiusMm, 1e-6)
        << "the left hand's frame is not on the second device's circle";
    servo.stop();
    EXPECT_EQ(fake::last_force_n_of(1), Eigen::Vector3d::Zero()) << "force left on after stop";
    EXPECT_EQ(fake::last_force_n_of(2), Eigen::Vector3d::Zero()) << "force left on after stop";
  }
}

}  // namespace
}  // namespace liversim
