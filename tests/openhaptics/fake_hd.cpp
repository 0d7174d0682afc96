// A stand-in for the vendor's OpenHaptics HD runtime, built as a libHD.so of its own so that the
// driver's dlopen path runs in CI. It exports the HD functions the driver uses, with OpenHaptics
// 3.x's C signatures and constants, and emulates a PHANTOM Omni configured as "Default Device"
// and, once a test configures it (fake_hd_configure_second_device), a second one under another
// name, as Touch Setup names a second Omni (a left hand's):
// - a scheduler thread calls the scheduled callbacks at about 1 kHz;
// - each stylus runs round a 20 mm circle (kCentreMm, kRadiusMm, kTurnRadPerS; the second one's
//   centre kSecondDeviceOffsetMm away) with the matching velocity, latched at hdBeginFrame like
//   the device's state;
// - as in OpenHaptics, hdInitDevice and hdMakeCurrentDevice make a device current, and the
//   parameter calls (hdGet*, hdSetDoublev, hdEnable) act on the current device;
// - the force set in a frame is applied at hdEndFrame, and only while HD_FORCE_OUTPUT is enabled;
// - errors form a stack that hdGetError pops, most recent first.
// The fake_hd_* functions are test hooks, looked up by the tests with dlsym.
// It declares the HD types and constants itself, from OpenHaptics' hdDefines.h, rather than
// sharing the driver's: a wrong value shared by both would pass unnoticed.

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace {

using HHD = unsigned int;
using HDenum = unsigned int;
using HDerror = unsigned int;
using HDCallbackCode = unsigned int;
using HDSchedulerHandle = unsigned long;
using HDSchedulerCallback = HDCallbackCode (*)(void*);
struct HDErrorInfo {
  HDerror errorCode;
  int internalErrorCode;
  HHD hHD;
};

constexpr HHD kHandle = 1;  // the default device's; the second device's is 2
constexpr HHD HD_INVALID_HANDLE = 0xFFFFFFFF;
constexpr HDCallbackCode HD_CALLBACK_DONE = 0;
constexpr HDerror HD_INVALID_ENUM = 0x0100;
constexpr HDerror HD_BAD_HANDLE = 0x0104;
constexpr HDerror HD_DEVICE_FAULT = 0x0300;
constexpr HDerror HD_DEVICE_ALREADY_INITIATED = 0x0301;
constexpr HDenum HD_CURRENT_BUTTONS = 0x2000;
constexpr HDenum HD_CURRENT_POSITION = 0x2050;
constexpr HDenum HD_CURRENT_VELOCITY = 0x2051;
constexpr HDenum HD_CURRENT_TRANSFORM = 0x2052;
constexpr HDenum HD_DEVICE_MODEL_TYPE = 0x2501;
constexpr HDenum HD_USABLE_WORKSPACE_DIMENSIONS = 0x2551;
constexpr HDenum HD_NOMINAL_MAX_STIFFNESS = 0x2602;
constexpr HDenum HD_NOMINAL_MAX_FORCE = 0x2603;
constexpr HDenum HD_NOMINAL_MAX_CONTINUOUS_FORCE = 0x2604;
constexpr HDenum HD_NOMINAL_MAX_DAMPING = 0x2609;
constexpr HDenum HD_CURRENT_FORCE = 0x2700;
constexpr HDenum HD_FORCE_OUTPUT = 0x4000;
constexpr HDenum HD_CALIBRATION_OK = 0x5000;

// The stylus path (the tests know it too).
constexpr double kCentreMm[3] = {0.0, 0.0, -20.0};
constexpr double kRadiusMm = 20.0;
constexpr double kTurnRadPerS = 3.14159265358979323846;  // one turn in 2 s
constexpr double kSecondDeviceOffsetMm[3] = {-60.0, 0.0, 0.0};

// What OpenHaptics reports, in its units: N, N/mm, N·s/mm, mm.
struct Model {
  std::string name = "PHANTOM Omni";
  double max_force_n = 3.3;
  double max_continuous_force_n = 0.88;
  double max_stiffness_n_per_mm = 0.7;
  double max_damping_n_s_per_mm = 0.005;
  double usable_workspace_mm[6] = {-80.0, -60.0, -35.0, 80.0, 60.0, 35.0};
};

struct Scheduled {
  HDSchedulerHandle handle;
  HDSchedulerCallback callback;
  void* data;
};

// One device's state.
struct Device {
  std::string configuration;  // its name in Touch Setup; empty: not configured
  bool initialised = false;
  bool force_output = false;
  int buttons = 0;
  // The stylus's rotation in the device frame, column-major 3 × 3 (the gimbal angles).
  double rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  double centre_mm[3] = {kCentreMm[0], kCentreMm[1], kCentreMm[2]};
  std::chrono::steady_clock::time_point epoch = std::chrono::steady_clock::now();
  int frame_depth = 0;
  double position_mm[3] = {0, 0, 0};
  double velocity_mm_per_s[3] = {0, 0, 0};
  double pending_force_n[3] = {0, 0, 0};
  double applied_force_n[3] = {0, 0, 0};
};

struct Fake {
  std::mutex mutex;  // everything below up to the scheduler's own state
  Model model;
  HDenum calibration = HD_CALIBRATION_OK;
  HDErrorInfo init_failure{0, 0, 0};
  Device devices[2];  // handle h is devices[h - 1]
  HHD current = kHandle;
  int init_calls = 0;
  std::vector<HDErrorInfo> errors;             // the stack, top at the back
  std::vector<HDErrorInfo> at_next_frame_end;  // injected errors waiting for hdEndFrame

  std::mutex callbacks_mutex;  // held while callbacks run: after hdUnschedule none is running
  std::vector<Scheduled> callbacks;
  HDSchedulerHandle next_handle = 1;
  unsigned short last_priority = 0;
  std::thread scheduler;
  std::atomic<bool> scheduler_running{false};
  std::atomic<long> ticks{0};

  Fake() { devices[0].configuration = "Default Device"; }
  Device& of(HHD handle) { return devices[handle - 1]; }
  Device& current_device() { return of(current); }
};

Fake& fake() {
  static Fake* instance = new Fake;  // never destroyed: the scheduler may outlive static teardown
  return *instance;
}

void push_error(Fake& f, HDerror code, int internal = 0) {
  f.errors.push_back({code, internal, f.current});
}

bool check_handle(Fake& f, HHD handle) {
  if ((handle == 1 || handle == 2) && f.of(handle).initialised) return true;
  push_error(f, HD_BAD_HANDLE);
  return false;
}

// The stylus state now, on its circle.
void latch_state(Device& d) {
  const double t_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - d.epoch).count();
  const double angle = kTurnRadPerS * t_s;
  d.position_mm[0] = d.centre_mm[0] + kRadiusMm * std::cos(angle);
  d.position_mm[1] = d.centre_mm[1] + kRadiusMm * std::sin(angle);
  d.position_mm[2] = d.centre_mm[2];
  d.velocity_mm_per_s[0] = -kRadiusMm * kTurnRadPerS * std::sin(angle);
  d.velocity_mm_per_s[1] = kRadiusMm * kTurnRadPerS * std::cos(angle);
  d.velocity_mm_per_s[2] = 0.0;
}

void run_scheduler() {
  Fake& f = fake();
  auto next = std::chrono::steady_clock::now();
  while (f.scheduler_running.load()) {
    next += std::chrono::milliseconds(1);
    {
      const std::lock_guard lock(f.callbacks_mutex);
      for (std::size_t i = 0; i < f.callbacks.size();) {
        if (f.callbacks[i].callback(f.callbacks[i].data) == HD_CALLBACK_DONE)
          f.callbacks.erase(f.callbacks.begin() + static_cast<std::ptrdiff_t>(i));
        else
          ++i;
      }
    }
    f.ticks.fetch_add(1);
    std::this_thread::sleep_until(next);
  }
}

}  // namespace

extern "C" {

// ---- The HD API ----

HHD hdInitDevice(const char* name) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  ++f.init_calls;
  if (f.init_failure.errorCode != 0) {
    f.errors.push_back(f.init_failure);
    return HD_INVALID_HANDLE;
  }
  // HD_DEFAULT_DEVICE (null) is the device configured as "Default Device".
  const std::string configuration = name != nullptr ? name : "Default Device";
  HHD handle = 0;
  for (HHD h : {1u, 2u})
    if (!configuration.empty() && f.of(h).configuration == configuration) handle = h;
  if (handle == 0) {
    push_error(f, HD_DEVICE_FAULT, -1);  // no such configuration
    return HD_INVALID_HANDLE;
  }
  Device& d = f.of(handle);
  if (d.initialised) {
    push_error(f, HD_DEVICE_ALREADY_INITIATED);
    return HD_INVALID_HANDLE;
  }
  d.initialised = true;
  d.force_output = false;
  d.epoch = std::chrono::steady_clock::now();
  f.current = handle;
  return handle;
}

void hdDisableDevice(HHD handle) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  if (!check_handle(f, handle)) return;
  f.of(handle).initialised = false;
  f.of(handle).force_output = false;
}

void hdMakeCurrentDevice(HHD handle) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  if (check_handle(f, handle)) f.current = handle;
}

void hdBeginFrame(HHD handle) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  if (!check_handle(f, handle)) return;
  if (f.of(handle).frame_depth++ == 0) latch_state(f.of(handle));
}

void hdEndFrame(HHD handle) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  if (!check_handle(f, handle)) return;
  Device& d = f.of(handle);
  if (d.frame_depth == 0 || --d.frame_depth > 0) return;
  for (int i = 0; i < 3; ++i) d.applied_force_n[i] = d.force_output ? d.pending_force_n[i] : 0.0;
  // Injected errors are the default device's.
  if (handle != kHandle) return;
  f.errors.insert(f.errors.end(), f.at_next_frame_end.begin(), f.at_next_frame_end.end());
  f.at_next_frame_end.clear();
}

HDErrorInfo hdGetError() {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  if (f.errors.empty()) return {0, 0, f.current};
  const HDErrorInfo error = f.errors.back();
  f.errors.pop_back();
  return error;
}

void hdEnable(HDenum capability) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  if (capability == HD_FORCE_OUTPUT)
    f.current_device().force_output = true;
  else
    push_error(f, HD_INVALID_ENUM);
}

void hdGetDoublev(HDenum parameter, double* values) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  Device& d = f.current_device();
  if (d.frame_depth == 0) latch_state(d);
  switch (parameter) {
    case HD_CURRENT_POSITION:
      std::memcpy(values, d.position_mm, sizeof d.position_mm);
      return;
    case HD_CURRENT_VELOCITY:
      std::memcpy(values, d.velocity_mm_per_s, sizeof d.velocity_mm_per_s);
      return;
    case HD_CURRENT_TRANSFORM:  // column-major: the rotation, translation in 12-14
      for (int i = 0; i < 16; ++i) values[i] = i == 15 ? 1.0 : 0.0;
      for (int column = 0; column < 3; ++column)
        for (int row = 0; row < 3; ++row) values[4 * column + row] = d.rotation[3 * column + row];
      std::memcpy(values + 12, d.position_mm, sizeof d.position_mm);
      return;
    case HD_NOMINAL_MAX_FORCE:
      *values = f.model.max_force_n;
      return;
    case HD_NOMINAL_MAX_CONTINUOUS_FORCE:
      *values = f.model.max_continuous_force_n;
      return;
    case HD_NOMINAL_MAX_STIFFNESS:
      *values = f.model.max_stiffness_n_per_mm;
      return;
    case HD_NOMINAL_MAX_DAMPING:
      *values = f.model.max_damping_n_s_per_mm;
      return;
    case HD_USABLE_WORKSPACE_DIMENSIONS:
      std::memcpy(values, f.model.usable_workspace_mm, sizeof f.model.usable_workspace_mm);
      return;
    default:
      push_error(f, HD_INVALID_ENUM);
  }
}

void hdGetIntegerv(HDenum parameter, int* values) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  if (parameter == HD_CURRENT_BUTTONS)
    *values = f.current_device().buttons;
  else
    push_error(f, HD_INVALID_ENUM);
}

const char* hdGetString(HDenum parameter) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  if (parameter == HD_DEVICE_MODEL_TYPE) return f.model.name.c_str();
  push_error(f, HD_INVALID_ENUM);
  return nullptr;
}

void hdSetDoublev(HDenum parameter, const double* values) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  if (parameter == HD_CURRENT_FORCE)
    std::memcpy(f.current_device().pending_force_n, values,
                sizeof f.current_device().pending_force_n);
  else
    push_error(f, HD_INVALID_ENUM);
}

HDenum hdCheckCalibration() {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  return f.calibration;
}

void hdStartScheduler() {
  Fake& f = fake();
  if (f.scheduler_running.exchange(true)) return;
  f.scheduler = std::thread(run_scheduler);
}

void hdStopScheduler() {
  Fake& f = fake();
  if (!f.scheduler_running.exchange(false)) return;
  f.scheduler.join();
}

HDSchedulerHandle hdScheduleAsynchronous(HDSchedulerCallback callback, void* data,
                                         unsigned short priority) {
  Fake& f = fake();
  const std::lock_guard lock(f.callbacks_mutex);
  f.last_priority = priority;
  f.callbacks.push_back({f.next_handle, callback, data});
  return f.next_handle++;
}

void hdUnschedule(HDSchedulerHandle handle) {
  Fake& f = fake();
  const std::lock_guard lock(f.callbacks_mutex);
  std::erase_if(f.callbacks, [&](const Scheduled& s) { return s.handle == handle; });
}

// ---- Test hooks ----

// Back to a calibrated PHANTOM Omni with nothing pending (the scheduler must be stopped).
void fake_hd_reset() {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  f.model = Model{};
  f.calibration = HD_CALIBRATION_OK;
  f.init_failure = {0, 0, 0};
  f.errors.clear();
  f.at_next_frame_end.clear();
  for (Device& d : f.devices) {
    for (int i = 0; i < 9; ++i) d.rotation[i] = i % 4 == 0 ? 1.0 : 0.0;
    d.buttons = 0;
    for (double& force : d.applied_force_n) force = 0.0;
    for (double& force : d.pending_force_n) force = 0.0;
  }
  // The second device is configured only by the tests that use it (a device still open keeps
  // its configuration).
  if (!f.devices[1].initialised) f.devices[1].configuration.clear();
}

// A second device, configured under this name in Touch Setup (a left hand's Omni), its circle
// centred kSecondDeviceOffsetMm from the first's.
void fake_hd_configure_second_device(const char* name) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  Device& d = f.devices[1];
  d.configuration = name;
  for (int i = 0; i < 3; ++i) d.centre_mm[i] = kCentreMm[i] + kSecondDeviceOffsetMm[i];
}

// The force applied at the last hdEndFrame of device `handle` (1: the default device), N.
void fake_hd_last_force_of(unsigned int handle, double force_n[3]) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  std::memcpy(force_n, f.of(handle).applied_force_n, sizeof f.of(handle).applied_force_n);
}

int fake_hd_device_enabled_of(unsigned int handle) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  return f.of(handle).initialised ? 1 : 0;
}

// hdInitDevice fails with this error (code 0: it succeeds again).
void fake_hd_fail_init(HDerror code, int internal_code) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  f.init_failure = {code, internal_code, HD_INVALID_HANDLE};
}

// Another device, in OpenHaptics' units (N, N/mm, N·s/mm).
void fake_hd_set_model(const char* name, double max_force_n, double max_continuous_force_n,
                       double max_stiffness_n_per_mm, double max_damping_n_s_per_mm) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  f.model.name = name;
  f.model.max_force_n = max_force_n;
  f.model.max_continuous_force_n = max_continuous_force_n;
  f.model.max_stiffness_n_per_mm = max_stiffness_n_per_mm;
  f.model.max_damping_n_s_per_mm = max_damping_n_s_per_mm;
}

void fake_hd_set_calibration(HDenum status) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  f.calibration = status;
}

// The stylus's rotation, column-major 3 × 3, as HD_CURRENT_TRANSFORM gives it.
void fake_hd_set_stylus_rotation(const double column_major[9]) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  std::memcpy(f.devices[0].rotation, column_major, sizeof f.devices[0].rotation);
}

void fake_hd_set_buttons(int buttons) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  f.devices[0].buttons = buttons;
}

// The device raises this error at the end of the next frame.
void fake_hd_inject_error(HDerror code, int internal_code) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  f.at_next_frame_end.push_back({code, internal_code, kHandle});
}

// The force applied at the last hdEndFrame, N.
void fake_hd_last_force(double force_n[3]) {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  std::memcpy(force_n, f.devices[0].applied_force_n, sizeof f.devices[0].applied_force_n);
}

int fake_hd_scheduler_running() {
  return fake().scheduler_running.load() ? 1 : 0;
}

int fake_hd_scheduled_callbacks() {
  Fake& f = fake();
  const std::lock_guard lock(f.callbacks_mutex);
  return static_cast<int>(f.callbacks.size());
}

unsigned short fake_hd_last_priority() {
  Fake& f = fake();
  const std::lock_guard lock(f.callbacks_mutex);
  return f.last_priority;
}

int fake_hd_device_enabled() {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  return f.devices[0].initialised ? 1 : 0;
}

int fake_hd_force_output_enabled() {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  return f.devices[0].force_output ? 1 : 0;
}

int fake_hd_init_calls() {
  Fake& f = fake();
  const std::lock_guard lock(f.mutex);
  return f.init_calls;
}

long fake_hd_ticks() {
  return fake().ticks.load();
}

}  // extern "C"
