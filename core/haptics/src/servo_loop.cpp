#include "liversim/haptics/servo_loop.h"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <cmath>
#include <stdexcept>

namespace liversim {

ServoLoop::ServoLoop(HapticDevice& device, Options options)
    : device_(device),
      options_(options),
      renderer_(device.limits(), options.safety),
      epoch_(std::chrono::steady_clock::now()),
      log_(options.log_capacity) {
  if (auto problem = validate(options_.safety)) throw std::invalid_argument(*problem);
  if (auto problem = validate(options_.mapping)) throw std::invalid_argument(*problem);
}

ServoLoop::~ServoLoop() {
  stop();
}

double ServoLoop::now_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - epoch_).count();
}

void ServoLoop::start() {
  if (running_.load()) return;
  stop_requested_ = false;
  running_ = true;
  if (device_.start_own_clock(&ServoLoop::tick_from_device, this)) {
    own_clock_ = true;
    return;
  }
  thread_ = std::thread([this] { run(); });
}

void ServoLoop::stop() {
  if (!running_.load()) return;
  stop_requested_ = true;
  if (own_clock_.load()) {
    device_.stop_own_clock();  // zeroes the force on its way out
    own_clock_ = false;
  }
  if (thread_.joinable()) thread_.join();
  running_ = false;
}

void ServoLoop::tick_from_device(void* self) {
  auto* loop = static_cast<ServoLoop*>(self);
  loop->tick(loop->now_s());
}

void ServoLoop::run() {
  if (options_.real_time_priority) {
    sched_param priority{};
    priority.sched_priority = sched_get_priority_min(SCHED_FIFO);
    pthread_setschedparam(pthread_self(), SCHED_FIFO, &priority);  // refused without rights: fine
  }
  const long period_ns = std::lround(1e9 / options_.safety.nominal_rate_hz);
  timespec deadline{};
  clock_gettime(CLOCK_MONOTONIC, &deadline);
  while (!stop_requested_.load(std::memory_order_relaxed)) {
    tick(now_s());
    deadline.tv_nsec += period_ns;
    while (deadline.tv_nsec >= 1'000'000'000L) {
      deadline.tv_nsec -= 1'000'000'000L;
      ++deadline.tv_sec;
    }
    // Late by more than a period: start again from now rather than tick in a burst to catch up.
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    const double late_s =
        (now.tv_sec - deadline.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec - deadline.tv_nsec);
    if (late_s > 1e-9 * static_cast<double>(period_ns)) deadline = now;
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr);
  }
  device_.write_force(Eigen::Vector3d::Zero());
}

void ServoLoop::tick(double now_s) {
  ServoFrame frame;
  frame.time_s = now_s;
  if (fatal_.load(std::memory_order_relaxed)) return;  // the device is gone: nothing to drive
  const DeviceStatus read = device_.read(now_s, frame.sample);
  if (!read.ok()) ++device_faults_;
  if (read.fault == DeviceFault::fatal) {
    fatal_ = true;
    fault_message_ = read.message;
    renderer_.hold_zero(true);
    device_.write_force(Eigen::Vector3d::Zero());
    return;
  }
  if (models_.update()) renderer_.accept(models_.front());
  renderer_.hold_zero(paused_.load(std::memory_order_relaxed));
  frame.force_n = renderer_.command(now_s, frame.sample);
  if (read.fault ==
      DeviceFault::recoverable) {  // zero now; the force ramps back from the next tick
    fault_message_ = read.message;
    renderer_.restart_ramp();
    frame.force_n.setZero();
  }
  const DeviceStatus wrote = device_.write_force(frame.force_n);
  if (wrote.fault == DeviceFault::fatal) {
    fatal_ = true;
    fault_message_ = wrote.message;
    renderer_.hold_zero(true);
  }
  frames_.back() = frame;
  frames_.publish();
  log_.push(frame);
  if (now_s - last_stats_s_ >= 0.05) {
    ServoStats& out = stats_.back();
    out = renderer_.stats();
    out.device_faults = device_faults_;
    stats_.publish();
    last_stats_s_ = now_s;
  }
}

void ServoLoop::publish(LocalForceModel model, double published_s) {
  model.published_s = published_s;
  models_.back() = to_device(model, options_.mapping);
  models_.publish();
}

bool ServoLoop::newest_frame(ServoFrame& frame) {
  have_frame_ = frames_.update() || have_frame_;
  if (have_frame_) frame = frames_.front();
  return have_frame_;
}

ServoStats ServoLoop::stats() {
  std::lock_guard lock(stats_reader_);
  stats_.update();
  return stats_.front();
}

std::string ServoLoop::device_fault() {
  return fatal_.load() ? std::string(fault_message_.load()) : std::string();
}

}  // namespace liversim
