#include "liversim/haptics/openhaptics_device.h"

#include <dlfcn.h>

#include <Eigen/Dense>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <mutex>
#include <thread>

namespace liversim {
namespace openhaptics {

// The HD API's types and the constants used here, as in OpenHaptics 3.x hdDefines.h (checked
// against SensAble's header; some public re-declarations carry wrong values).
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

constexpr HHD HD_INVALID_HANDLE = 0xFFFFFFFF;
constexpr HDerror HD_SUCCESS = 0x0000;
constexpr HDCallbackCode HD_CALLBACK_CONTINUE = 1;
constexpr unsigned short HD_MAX_SCHEDULER_PRIORITY = 65535;
constexpr HDenum HD_CURRENT_BUTTONS = 0x2000;
constexpr HDenum HD_CURRENT_POSITION = 0x2050;
constexpr HDenum HD_CURRENT_VELOCITY = 0x2051;
constexpr HDenum HD_CURRENT_TRANSFORM = 0x2052;
constexpr HDenum HD_DEVICE_MODEL_TYPE = 0x2501;
constexpr HDenum HD_USABLE_WORKSPACE_DIMENSIONS = 0x2551;
constexpr HDenum HD_NOMINAL_MAX_STIFFNESS = 0x2602;  // N/mm
constexpr HDenum HD_NOMINAL_MAX_FORCE = 0x2603;      // N
constexpr HDenum HD_NOMINAL_MAX_CONTINUOUS_FORCE = 0x2604;
constexpr HDenum HD_NOMINAL_MAX_DAMPING = 0x2609;  // N·s/mm
constexpr HDenum HD_CURRENT_FORCE = 0x2700;
constexpr HDenum HD_FORCE_OUTPUT = 0x4000;
constexpr HDenum HD_CALIBRATION_OK = 0x5000;

struct Api {
  HHD (*hdInitDevice)(const char* name);
  void (*hdDisableDevice)(HHD);
  void (*hdMakeCurrentDevice)(HHD);
  void (*hdBeginFrame)(HHD);
  void (*hdEndFrame)(HHD);
  HDErrorInfo (*hdGetError)();
  void (*hdEnable)(HDenum);
  void (*hdGetDoublev)(HDenum, double*);
  void (*hdGetIntegerv)(HDenum, int*);
  const char* (*hdGetString)(HDenum);
  void (*hdSetDoublev)(HDenum, const double*);
  HDenum (*hdCheckCalibration)();
  void (*hdStartScheduler)();
  void (*hdStopScheduler)();
  HDSchedulerHandle (*hdScheduleAsynchronous)(HDSchedulerCallback, void*, unsigned short);
  void (*hdUnschedule)(HDSchedulerHandle);
};

namespace {

struct HdError {
  HDerror code;
  const char* name;
  bool recoverable;
  const char* status_message;  // static: the servo path must not allocate
};

// The recoverable ones are those OpenSurgSim's and CHAI3D's drivers ride through.
constexpr std::array<HdError, 21> kHdErrors{{
    {0x0100, "HD_INVALID_ENUM", false, "OpenHaptics HD_INVALID_ENUM: force output stopped"},
    {0x0101, "HD_INVALID_VALUE", false, "OpenHaptics HD_INVALID_VALUE: force output stopped"},
    {0x0102, "HD_INVALID_OPERATION", false,
     "OpenHaptics HD_INVALID_OPERATION: force output stopped"},
    {0x0103, "HD_INVALID_INPUT_TYPE", false,
     "OpenHaptics HD_INVALID_INPUT_TYPE: force output stopped"},
    {0x0104, "HD_BAD_HANDLE", false, "OpenHaptics HD_BAD_HANDLE: force output stopped"},
    {0x0200, "HD_WARM_MOTORS", true, "OpenHaptics HD_WARM_MOTORS: motors warm, force reduced"},
    {0x0201, "HD_EXCEEDED_MAX_FORCE", true,
     "OpenHaptics HD_EXCEEDED_MAX_FORCE: force above the device's maximum"},
    {0x0202, "HD_EXCEEDED_MAX_FORCE_IMPULSE", true,
     "OpenHaptics HD_EXCEEDED_MAX_FORCE_IMPULSE: force changed too fast"},
    {0x0203, "HD_EXCEEDED_MAX_VELOCITY", true,
     "OpenHaptics HD_EXCEEDED_MAX_VELOCITY: stylus moved too fast"},
    {0x0204, "HD_FORCE_ERROR", true, "OpenHaptics HD_FORCE_ERROR: force not rendered"},
    {0x0300, "HD_DEVICE_FAULT", false, "OpenHaptics HD_DEVICE_FAULT: force output stopped"},
    {0x0301, "HD_DEVICE_ALREADY_INITIATED", false,
     "OpenHaptics HD_DEVICE_ALREADY_INITIATED: force output stopped"},
    {0x0302, "HD_COMM_ERROR", false, "OpenHaptics HD_COMM_ERROR: device lost, force stopped"},
    {0x0303, "HD_COMM_CONFIG_ERROR", false,
     "OpenHaptics HD_COMM_CONFIG_ERROR: force output stopped"},
    {0x0304, "HD_TIMER_ERROR", false, "OpenHaptics HD_TIMER_ERROR: force output stopped"},
    {0x0400, "HD_ILLEGAL_BEGIN", false, "OpenHaptics HD_ILLEGAL_BEGIN: force output stopped"},
    {0x0401, "HD_ILLEGAL_END", false, "OpenHaptics HD_ILLEGAL_END: force output stopped"},
    {0x0402, "HD_FRAME_ERROR", false, "OpenHaptics HD_FRAME_ERROR: force output stopped"},
    {0x0500, "HD_INVALID_PRIORITY", false, "OpenHaptics HD_INVALID_PRIORITY: force stopped"},
    {0x0501, "HD_SCHEDULER_FULL", false, "OpenHaptics HD_SCHEDULER_FULL: force output stopped"},
    {0x0600, "HD_INVALID_LICENSE", false, "OpenHaptics HD_INVALID_LICENSE: force output stopped"},
}};
constexpr HdError kUnknownHdError{0, "an unknown error", false,
                                  "OpenHaptics device error: force output stopped"};

const HdError& hd_error(HDerror code) {
  for (const HdError& error : kHdErrors)
    if (error.code == code) return error;
  return kUnknownHdError;
}

// Errors the runtime stacks up between two checks; more than this are left for the next check so
// that a runaway stack cannot hold up the servo tick.
constexpr int kMaxErrorsPerCheck = 16;

// Pops and drops pending errors (stale ones would read as failures of the next call).
void discard_errors(const Api& api) {
  for (int i = 0; i < kMaxErrorsPerCheck && api.hdGetError().errorCode != HD_SUCCESS; ++i) {
  }
}

const char* const kOtherDevices = "the mouse, scripted and replay devices are still available.";
const char* const kOtherDevicesSentence =
    "The mouse, scripted and replay devices are still available.";

struct Runtime {
  const Api* api = nullptr;
  std::string problem;
};

template <typename Function>
bool bind(void* library, const char* symbol, Function& function) {
  function = reinterpret_cast<Function>(dlsym(library, symbol));
  return function != nullptr;
}

// dlopen and bind once per library name; what loads is never closed (the vendor driver fails when
// loaded twice). A library that is absent is tried again next time: it may have been installed.
Runtime load_runtime(const std::string& library) {
  static std::mutex mutex;
  static auto* loaded = new std::map<std::string, Runtime>;  // never freed, like the libraries
  const std::lock_guard lock(mutex);
  if (const auto found = loaded->find(library); found != loaded->end()) return found->second;

  // RTLD_NOW: a runtime with unresolved dependencies fails here, with dlerror's reason, instead of
  // aborting the process at its first call.
  void* handle = dlopen(library.c_str(), RTLD_NOW | RTLD_GLOBAL);
  if (handle == nullptr) {
    const char* reason = dlerror();
    return {nullptr, "The OpenHaptics runtime " + library + " could not be loaded (" +
                         (reason ? reason : "not found") +
                         "): install OpenHaptics to use the Phantom Omni / Touch; " +
                         kOtherDevices};
  }
  auto api = std::make_unique<Api>();
  const char* missing = nullptr;
  auto need = [&](const char* symbol, auto& function) {
    if (missing == nullptr && !bind(handle, symbol, function)) missing = symbol;
  };
  need("hdInitDevice", api->hdInitDevice);
  need("hdDisableDevice", api->hdDisableDevice);
  need("hdMakeCurrentDevice", api->hdMakeCurrentDevice);
  need("hdBeginFrame", api->hdBeginFrame);
  need("hdEndFrame", api->hdEndFrame);
  need("hdGetError", api->hdGetError);
  need("hdEnable", api->hdEnable);
  need("hdGetDoublev", api->hdGetDoublev);
  need("hdGetIntegerv", api->hdGetIntegerv);
  need("hdGetString", api->hdGetString);
  need("hdSetDoublev", api->hdSetDoublev);
  need("hdCheckCalibration", api->hdCheckCalibration);
  need("hdStartScheduler", api->hdStartScheduler);
  need("hdStopScheduler", api->hdStopScheduler);
  need("hdScheduleAsynchronous", api->hdScheduleAsynchronous);
  need("hdUnschedule", api->hdUnschedule);
  Runtime runtime;
  if (missing != nullptr)
    runtime.problem = "The OpenHaptics runtime " + library + " lacks the function " + missing +
                      " (not an OpenHaptics HD runtime?): the Phantom Omni / Touch cannot be " +
                      "used; " + kOtherDevices;
  else
    runtime.api = api.release();  // never freed, like the library
  return loaded->emplace(library, runtime).first->second;
}

double positive_or(double value, double fallback) {
  return std::isfinite(value) && value > 0.0 ? value : fallback;
}

// The device's nominal limits in SI units. A limit the runtime does not report keeps the default
// (the PHANTOM Omni's), so that a missing value never reads as a zero force or stiffness.
DeviceLimits read_limits(const Api& api) {
  constexpr double kUnread = std::numeric_limits<double>::quiet_NaN();
  double max_force_n = kUnread, max_continuous_force_n = kUnread;
  double max_stiffness_n_per_mm = kUnread, max_damping_n_s_per_mm = kUnread;
  std::array<double, 6> workspace_mm;  // min x, y, z, then max x, y, z
  workspace_mm.fill(kUnread);
  api.hdGetDoublev(HD_NOMINAL_MAX_FORCE, &max_force_n);
  api.hdGetDoublev(HD_NOMINAL_MAX_CONTINUOUS_FORCE, &max_continuous_force_n);
  api.hdGetDoublev(HD_NOMINAL_MAX_STIFFNESS, &max_stiffness_n_per_mm);
  api.hdGetDoublev(HD_NOMINAL_MAX_DAMPING, &max_damping_n_s_per_mm);
  api.hdGetDoublev(HD_USABLE_WORKSPACE_DIMENSIONS, workspace_mm.data());

  DeviceLimits limits;
  limits.max_force_n = positive_or(max_force_n, limits.max_force_n);
  limits.max_continuous_force_n =
      positive_or(max_continuous_force_n, limits.max_continuous_force_n);
  limits.max_stiffness_n_per_m =
      positive_or(max_stiffness_n_per_mm * 1000.0, limits.max_stiffness_n_per_m);
  limits.max_damping_n_s_per_m =
      positive_or(max_damping_n_s_per_mm * 1000.0, limits.max_damping_n_s_per_m);
  // The sphere through the corners of the usable box: every reachable point lies within it (about
  // 106 mm for the Omni's 160 x 120 x 70 mm box).
  const double half_x = 0.5 * (workspace_mm[3] - workspace_mm[0]);
  const double half_y = 0.5 * (workspace_mm[4] - workspace_mm[1]);
  const double half_z = 0.5 * (workspace_mm[5] - workspace_mm[2]);
  limits.workspace_radius_mm = positive_or(
      std::sqrt(half_x * half_x + half_y * half_y + half_z * half_z), limits.workspace_radius_mm);
  return limits;
}

// How long stop_own_clock() waits for the servo tick that writes the zero force.
constexpr auto kZeroForceWait = std::chrono::milliseconds(200);

}  // namespace
}  // namespace openhaptics

using namespace openhaptics;

OpenHapticsOpening open_openhaptics_device(const std::string& library, const char* device_name) {
  const Runtime runtime = load_runtime(library);
  if (runtime.api == nullptr) return {nullptr, runtime.problem};
  const Api& api = *runtime.api;

  discard_errors(api);
  const HHD handle = api.hdInitDevice(device_name);
  const HDErrorInfo error = api.hdGetError();
  if (error.errorCode != HD_SUCCESS || handle == HD_INVALID_HANDLE) {
    discard_errors(api);
    char code[16];
    std::snprintf(code, sizeof code, "0x%04x", error.errorCode);
    const std::string device =
        device_name ? "the device \"" + std::string(device_name) + "\"" : "the default device";
    return {nullptr, "OpenHaptics could not open " + device + ": hdInitDevice failed with error " +
                         code + " (" + hd_error(error.errorCode).name + "), internal code " +
                         std::to_string(error.internalErrorCode) +
                         ". Is the device connected and configured (Touch Setup)? " +
                         kOtherDevicesSentence};
  }

  api.hdMakeCurrentDevice(handle);
  api.hdEnable(HD_FORCE_OUTPUT);
  const DeviceLimits limits = read_limits(api);
  const char* model = api.hdGetString(HD_DEVICE_MODEL_TYPE);
  std::unique_ptr<OpenHapticsDevice> device(
      new OpenHapticsDevice(api, handle, model && *model ? model : "OpenHaptics device", limits));
  device->calibration_ok_.store(api.hdCheckCalibration() == HD_CALIBRATION_OK);
  // A parameter this device does not report (HD_INVALID_ENUM) has left its default in `limits`.
  discard_errors(api);
  return {std::move(device), ""};
}

OpenHapticsDevice::OpenHapticsDevice(const Api& api, unsigned int device_handle, std::string name,
                                     DeviceLimits limits)
    : api_(api), device_handle_(device_handle), name_(std::move(name)), limits_(limits) {}

OpenHapticsDevice::~OpenHapticsDevice() {
  if (own_clock_running_.load())
    stop_own_clock();
  else
    zero_force_in_own_frame();
  api_.hdMakeCurrentDevice(device_handle_);
  api_.hdDisableDevice(device_handle_);
  discard_errors(api_);
}

DeviceStatus OpenHapticsDevice::read(double /*time_s*/, DeviceSample& sample) {
  if (!own_clock_running_.load(std::memory_order_relaxed)) {
    api_.hdMakeCurrentDevice(device_handle_);
    api_.hdBeginFrame(device_handle_);
    capture_sample();
    api_.hdEndFrame(device_handle_);
    collect_errors();
  }
  sample = latest_;
  return take_status();
}

DeviceStatus OpenHapticsDevice::write_force(const Eigen::Vector3d& force_n) {
  const bool own_frame = !own_clock_running_.load(std::memory_order_relaxed);
  // In the scheduler's tick the other hand's device may have been made current since this one's
  // frame began: the force goes to this one.
  api_.hdMakeCurrentDevice(device_handle_);
  if (own_frame) api_.hdBeginFrame(device_handle_);
  // After a fatal error the force stays zero; a non-finite force is never sent to the motors.
  const bool refuse = status_.fault == DeviceFault::fatal || !force_n.allFinite();
  set_force(refuse ? Eigen::Vector3d::Zero() : force_n);
  if (own_frame) {
    api_.hdEndFrame(device_handle_);
    collect_errors();
  }
  if (status_.fault == DeviceFault::fatal) return status_;
  if (!force_n.allFinite())
    return {DeviceFault::recoverable, "OpenHaptics: non-finite force replaced by zero"};
  return {};
}

bool OpenHapticsDevice::start_own_clock(Tick tick, void* context) {
  if (tick == nullptr || own_clock_running_.load()) return false;
  tick_ = tick;
  tick_context_ = context;
  zero_force_requested_.store(false);
  zero_force_written_.store(false);
  api_.hdMakeCurrentDevice(device_handle_);
  servo_handle_ = api_.hdScheduleAsynchronous(&servo_callback, this, HD_MAX_SCHEDULER_PRIORITY);
  own_clock_running_.store(true);  // before the first tick: read() then returns its sample
  api_.hdStartScheduler();
  const HDErrorInfo error = api_.hdGetError();
  if (error.errorCode == HD_SUCCESS || hd_error(error.errorCode).recoverable) return true;
  api_.hdStopScheduler();
  api_.hdUnschedule(servo_handle_);
  own_clock_running_.store(false);
  tick_ = nullptr;
  return false;
}

void OpenHapticsDevice::stop_own_clock() {
  if (!own_clock_running_.load()) return;
  // The force is set inside a frame of the servo thread: ask the next tick to zero it and wait a
  // little for it (this thread may block; the servo thread does not).
  zero_force_requested_.store(true);
  const auto give_up = std::chrono::steady_clock::now() + kZeroForceWait;
  while (!zero_force_written_.load() && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  api_.hdStopScheduler();
  api_.hdUnschedule(servo_handle_);
  own_clock_running_.store(false);
  tick_ = nullptr;
  if (!zero_force_written_.load()) zero_force_in_own_frame();  // the scheduler had died
  collect_errors();
}

unsigned int OpenHapticsDevice::servo_callback(void* device) {
  static_cast<OpenHapticsDevice*>(device)->servo_tick();
  return HD_CALLBACK_CONTINUE;
}

void OpenHapticsDevice::servo_tick() {
  api_.hdMakeCurrentDevice(device_handle_);
  api_.hdBeginFrame(device_handle_);
  capture_sample();
  calibration_ok_.store(api_.hdCheckCalibration() == HD_CALIBRATION_OK, std::memory_order_relaxed);
  collect_errors();  // so that read() in `tick` reports them
  const bool stopping = zero_force_requested_.load();
  if (!stopping) tick_(tick_context_);
  api_.hdMakeCurrentDevice(device_handle_);  // the tick may have driven another device too
  if (stopping || status_.fault == DeviceFault::fatal) set_force(Eigen::Vector3d::Zero());
  api_.hdEndFrame(device_handle_);
  collect_errors();
  if (stopping) zero_force_written_.store(true);
}

void OpenHapticsDevice::capture_sample() {
  double position_mm[3] = {0.0, 0.0, 0.0};
  double velocity_mm_per_s[3] = {0.0, 0.0, 0.0};
  int buttons = 0;
  api_.hdGetDoublev(HD_CURRENT_POSITION, position_mm);
  api_.hdGetDoublev(HD_CURRENT_VELOCITY, velocity_mm_per_s);
  api_.hdGetIntegerv(HD_CURRENT_BUTTONS, &buttons);
  latest_.position_mm = Eigen::Vector3d(position_mm[0], position_mm[1], position_mm[2]);
  latest_.velocity_mm_per_s =
      Eigen::Vector3d(velocity_mm_per_s[0], velocity_mm_per_s[1], velocity_mm_per_s[2]);
  latest_.buttons = static_cast<std::uint32_t>(buttons);
  // The end effector's frame (column-major 4 × 4): at the home position it lines up with the
  // device's base frame, +z toward the user, so the stylus's tip is along its −z, as a tool's
  // working end is in the tool frame.
  double transform[16] = {};
  api_.hdGetDoublev(HD_CURRENT_TRANSFORM, transform);
  Eigen::Matrix3d rotation;
  for (int column = 0; column < 3; ++column)
    for (int row = 0; row < 3; ++row) rotation(row, column) = transform[4 * column + row];
  const Eigen::Quaterniond orientation(rotation);
  if (rotation.allFinite() && std::abs(rotation.determinant() - 1.0) < 1e-3)
    latest_.orientation = orientation.normalized();
  else
    latest_.orientation.reset();  // no rotation: the tool keeps its set direction
}

void OpenHapticsDevice::set_force(const Eigen::Vector3d& force_n) {
  const double force[3] = {force_n.x(), force_n.y(), force_n.z()};
  api_.hdSetDoublev(HD_CURRENT_FORCE, force);
}

void OpenHapticsDevice::collect_errors() {
  for (int i = 0; i < kMaxErrorsPerCheck; ++i) {
    const HDErrorInfo error = api_.hdGetError();
    if (error.errorCode == HD_SUCCESS) return;
    const HdError& known = hd_error(error.errorCode);
    // The first fatal error is kept; else the first recoverable one since the last read().
    if (status_.fault == DeviceFault::fatal) continue;
    if (!known.recoverable)
      status_ = {DeviceFault::fatal, known.status_message};
    else if (status_.fault == DeviceFault::none)
      status_ = {DeviceFault::recoverable, known.status_message};
  }
}

DeviceStatus OpenHapticsDevice::take_status() {
  const DeviceStatus status = status_;
  if (status_.fault == DeviceFault::recoverable) status_ = {};
  return status;
}

void OpenHapticsDevice::zero_force_in_own_frame() {
  api_.hdMakeCurrentDevice(device_handle_);
  api_.hdBeginFrame(device_handle_);
  set_force(Eigen::Vector3d::Zero());
  api_.hdEndFrame(device_handle_);
}

}  // namespace liversim
