#include "liversim/haptics/servo_loop.h"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <cmath>
#include <stdexcept>

namespace liversim {

ServoLoop::Channel::Channel(HapticDevice& device_in, const WorkspaceMapping& mapping_in,
                            const Options& options)
    : device(device_in),
      mapping(mapping_in),
      renderer(device_in.limits(), options.safety),
      log(options.log_capacity) {}

ServoLoop::ServoLoop(HapticDevice& device, Options options)
    : options_(options), epoch_(std::chrono::steady_clock::now()) {
  if (auto problem = validate(options_.safety)) throw std::invalid_argument(*problem);
  if (auto problem = validate(options_.mapping)) throw std::invalid_argument(*problem);
  channels_[hand_index(Hand::right)] =
      std::make_unique<Channel>(device, options_.mapping, options_);
}

ServoLoop::ServoLoop(HapticDevice& right, HapticDevice& left, Options options)
    : ServoLoop(right, options) {
  if (&right == &left)
    throw std::invalid_argument("one device cannot be in both hands: each hand needs its own");
  if (auto problem = validate(options_.left_mapping))
    throw std::invalid_argument("the left hand's device: " + *problem);
  channels_[hand_index(Hand::left)] =
      std::make_unique<Channel>(left, options_.left_mapping, options_);
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
  // A device with a scheduler of its own (OpenHaptics) ticks both hands' devices from it.
  for (const auto& channel : channels_)
    if (channel && channel->device.start_own_clock(&ServoLoop::tick_from_device, this)) {
      own_clock_device_ = &channel->device;
      own_clock_ = true;
      return;
    }
  thread_ = std::thread([this] { run(); });
}

void ServoLoop::stop() {
  if (!running_.load()) return;
  stop_requested_ = true;
  if (own_clock_.load()) {
    own_clock_device_->stop_own_clock();  // zeroes its force on its way out
    own_clock_ = false;
    own_clock_device_ = nullptr;
    for (const auto& channel : channels_)
      if (channel) channel->device.write_force(Eigen::Vector3d::Zero());
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
  for (const auto& channel : channels_)
    if (channel) channel->device.write_force(Eigen::Vector3d::Zero());
}

void ServoLoop::tick(double now_s) {
  const bool paused = paused_.load(std::memory_order_relaxed);
  const bool publish_stats = now_s - last_stats_s_ >= 0.05;
  for (const auto& channel : channels_)
    if (channel) tick(*channel, now_s, paused, publish_stats);
  if (publish_stats) last_stats_s_ = now_s;
}

void ServoLoop::tick(Channel& channel, double now_s, bool paused, bool publish_stats) {
  ServoFrame frame;
  frame.time_s = now_s;
  if (channel.fatal.load(std::memory_order_relaxed)) return;  // the device is gone
  const DeviceStatus read = channel.device.read(now_s, frame.sample);
  if (!read.ok()) ++channel.device_faults;
  if (read.fault == DeviceFault::fatal) {
    channel.fatal = true;
    channel.fault_message = read.message;
    channel.renderer.hold_zero(true);
    channel.device.write_force(Eigen::Vector3d::Zero());
    return;
  }
  if (channel.models.update()) channel.renderer.accept(channel.models.front());
  channel.renderer.hold_zero(paused);
  frame.force_n = channel.renderer.command(now_s, frame.sample);
  if (read.fault == DeviceFault::recoverable) {  // zero now; the force ramps back from the next
    channel.fault_message = read.message;
    channel.renderer.restart_ramp();
    frame.force_n.setZero();
  }
  const DeviceStatus wrote = channel.device.write_force(frame.force_n);
  if (wrote.fault == DeviceFault::fatal) {
    channel.fatal = true;
    channel.fault_message = wrote.message;
    channel.renderer.hold_zero(true);
  }
  channel.frames.back() = frame;
  channel.frames.publish();
  channel.log.push(frame);
  if (publish_stats) {
    ServoStats& out = channel.stats.back();
    out = channel.renderer.stats();
    out.device_faults = channel.device_faults;
    channel.stats.publish();
  }
}

void ServoLoop::publish(Hand hand, LocalForceModel model, double published_s) {
  Channel* channel = channels_[hand_index(hand)].get();
  if (!channel) return;
  model.published_s = published_s;
  channel->models.back() = to_device(model, channel->mapping);
  channel->models.publish();
}

bool ServoLoop::newest_frame(Hand hand, ServoFrame& frame) {
  Channel* channel = channels_[hand_index(hand)].get();
  if (!channel) return false;
  channel->have_frame = channel->frames.update() || channel->have_frame;
  if (channel->have_frame) frame = channel->frames.front();
  return channel->have_frame;
}

const WorkspaceMapping& ServoLoop::mapping(Hand hand) const {
  const Channel* channel = channels_[hand_index(hand)].get();
  return channel ? channel->mapping : options_.mapping;
}

ServoStats ServoLoop::stats(Hand hand) {
  Channel* channel = channels_[hand_index(hand)].get();
  if (!channel) return {};
  std::lock_guard lock(stats_reader_);
  channel->stats.update();
  return channel->stats.front();
}

std::string ServoLoop::device_fault(Hand hand) {
  const Channel* channel = channels_[hand_index(hand)].get();
  return channel && channel->fatal.load() ? std::string(channel->fault_message.load())
                                          : std::string();
}

bool ServoLoop::next_logged_frame(Hand hand, ServoFrame& frame) {
  Channel* channel = channels_[hand_index(hand)].get();
  return channel && channel->log.pop(frame);
}

std::uint64_t ServoLoop::dropped_log_frames(Hand hand) const {
  const Channel* channel = channels_[hand_index(hand)].get();
  return channel ? channel->log.dropped() : 0;
}

}  // namespace liversim
