#include "liversim/sessions/session_recorder.h"

#include <chrono>
#include <iterator>
#include <stdexcept>

namespace liversim {

SessionRecorder::SessionRecorder(SessionStore& store, const SessionStart& start,
                                 FrameSource next_frame, FrameSource next_left_frame,
                                 Options options)
    : store_(store),
      next_frame_(std::move(next_frame)),
      next_left_frame_(std::move(next_left_frame)),
      options_(options) {
  if (!(options_.commit_period_s > 0.0))
    throw std::invalid_argument("the commit period must be positive, not " +
                                std::to_string(options_.commit_period_s) + " s");
  if (static_cast<bool>(next_left_frame_) != start.left_hand.has_value())
    throw std::invalid_argument(start.left_hand
                                    ? "a session with a left hand needs its frames"
                                    : "left-hand frames need a session begun with a left hand");
  session_ = store_.begin_session(start);
  // A period's frames at up to 2 kHz without reallocating.
  const std::size_t period_frames =
      static_cast<std::size_t>(options_.commit_period_s * 2000.0) + 64;
  frame_batch_.reserve(period_frames);
  if (next_left_frame_) left_frame_batch_.reserve(period_frames);
  writer_ = std::thread([this] { run(); });
}

SessionRecorder::~SessionRecorder() {
  stop_writer();
}

void SessionRecorder::record_event(SessionEvent event) {
  std::lock_guard lock(mutex_);
  events_.push_back(std::move(event));
}

void SessionRecorder::record_inputs(std::vector<SimulationInput> inputs) {
  if (inputs.empty()) return;
  std::lock_guard lock(mutex_);
  if (inputs_.empty())
    inputs_ = std::move(inputs);
  else
    std::move(inputs.begin(), inputs.end(), std::back_inserter(inputs_));
}

std::string SessionRecorder::error() const {
  std::lock_guard lock(mutex_);
  return failure_ ? failure_->what() : std::string();
}

std::optional<StorageError> SessionRecorder::failure() const {
  std::lock_guard lock(mutex_);
  return failure_;
}

void SessionRecorder::stop_writer() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (writer_.joinable()) writer_.join();
}

bool SessionRecorder::finish(std::int64_t ended_unix_ms, const SessionServoFigures& servo,
                             const std::optional<SessionServoFigures>& left_servo) {
  stop_writer();  // its last pass wrote what was waiting then
  if (!error().empty()) return false;
  if (!write_waiting()) return false;  // what arrived since
  try {
    store_.end_session(session_, ended_unix_ms, servo,
                       next_left_frame_ ? left_servo : std::nullopt);
  } catch (const StorageError& e) {
    std::lock_guard lock(mutex_);
    failure_ = e;
    return false;
  }
  return true;
}

bool SessionRecorder::write_waiting() {
  frame_batch_.clear();
  ServoFrame frame;
  while (next_frame_(frame)) frame_batch_.push_back(frame);
  left_frame_batch_.clear();
  if (next_left_frame_)
    while (next_left_frame_(frame)) left_frame_batch_.push_back(frame);
  {
    std::lock_guard lock(mutex_);
    event_batch_.swap(events_);
    input_batch_.swap(inputs_);
  }
  try {
    if (!frame_batch_.empty()) store_.append_frames(session_, Hand::right, frame_batch_);
    if (!left_frame_batch_.empty()) store_.append_frames(session_, Hand::left, left_frame_batch_);
    if (!event_batch_.empty()) store_.append_events(session_, event_batch_);
    if (!input_batch_.empty()) store_.append_inputs(session_, input_batch_);
    if (!frame_batch_.empty() || !left_frame_batch_.empty() || !event_batch_.empty() ||
        !input_batch_.empty())
      store_.commit();
  } catch (const StorageError& e) {
    std::lock_guard lock(mutex_);
    failure_ = e;
    return false;
  }
  frames_written_ += static_cast<std::int64_t>(frame_batch_.size());
  left_frames_written_ += static_cast<std::int64_t>(left_frame_batch_.size());
  event_batch_.clear();
  input_batch_.clear();
  return true;
}

void SessionRecorder::run() {
  using Clock = std::chrono::steady_clock;
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(options_.commit_period_s));
  Clock::time_point next = Clock::now() + period;
  while (true) {
    bool stopping;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_until(lock, next, [this] { return stop_; });
      stopping = stop_;
    }
    if (!write_waiting() || stopping) return;
    next += period;
    // After a stall, the next period starts now rather than in a burst of catch-up commits.
    next = std::max(next, Clock::now());
  }
}

}  // namespace liversim
