#include "liversim/haptics/emulated_devices.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace liversim {

void ManualDevice::set(const Eigen::Vector3d& position_mm, std::uint32_t buttons) {
  input_.back() = Input{position_mm, buttons, placements_};
  input_.publish();
}

void ManualDevice::place(const Eigen::Vector3d& position_mm, std::uint32_t buttons) {
  input_.back() = Input{position_mm, buttons, ++placements_};
  input_.publish();
}

DeviceStatus ManualDevice::read(double time_s, DeviceSample& sample) {
  input_.update();
  const Input& input = input_.front();
  sample.position_mm = input.position_mm;
  const bool placed = input.placement != read_placement_;
  sample.buttons = input.buttons | (placed ? kRepositioned : 0u);
  read_placement_ = input.placement;
  const double dt_s = time_s - previous_s_;
  sample.velocity_mm_per_s = !placed && previous_s_ >= 0.0 && dt_s > 0.0
                                 ? Eigen::Vector3d((input.position_mm - previous_mm_) / dt_s)
                                 : Eigen::Vector3d::Zero();
  previous_mm_ = input.position_mm;
  previous_s_ = time_s;
  return {};
}

DeviceStatus ManualDevice::write_force(const Eigen::Vector3d& force_n) {
  force_.back() = force_n;
  force_.publish();
  return {};
}

Eigen::Vector3d ManualDevice::last_force_n() {
  force_.update();
  return force_.front();
}

namespace {
// A word of a file as a message shows it: at most 40 characters.
std::string shown_word(const std::string& word) {
  return word.size() > 40 ? word.substr(0, 37) + "..." : word;
}
}  // namespace

std::vector<TrajectoryPoint> load_trajectory(const std::filesystem::path& file) {
  return read_trajectory_file(file).points;
}

TrajectoryFile read_trajectory_file(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read the trajectory file " + file.string());
  TrajectoryFile read;
  std::vector<TrajectoryPoint>& points = read.points;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream fields(line);
    std::vector<std::string> words;
    for (std::string word; fields >> word;) words.push_back(word);
    if (words.empty()) continue;  // blank or comment
    auto problem = [&](const std::string& what) {
      return std::runtime_error(file.string() + ":" + std::to_string(number) + ": " + what +
                                " (expected: time_s x_mm y_mm z_mm buttons [qw qx qy qz] [tool])");
    };
    auto number_of = [&](const std::string& word) {
      double value = 0.0;
      const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
      if (error != std::errc() || end != word.data() + word.size())
        throw problem("'" + shown_word(word) + "' is not a number");
      return value;
    };
    if (words.size() < 5) throw problem("not five numbers");
    // After the buttons: four numbers, the orientation; then a word, the tool.
    const bool tool_sixth = words.size() >= 6 &&
                            std::find(kTrajectoryTools.begin(), kTrajectoryTools.end(), words[5]) !=
                                kTrajectoryTools.end();
    const bool with_orientation = words.size() >= 9 && !tool_sixth;
    const std::size_t tool_at = with_orientation ? 9 : 5;
    if (!with_orientation && !tool_sixth && words.size() > 6)
      throw problem("an orientation needs four numbers, qw qx qy qz");
    if (words.size() > tool_at + 1)
      throw problem((tool_at == 5 ? "more than six fields ('" : "more than ten fields ('") +
                    shown_word(words[tool_at + 1]) + "')");
    if (words.size() == tool_at + 1 && std::find(kTrajectoryTools.begin(), kTrajectoryTools.end(),
                                                 words[tool_at]) == kTrajectoryTools.end())
      throw problem("'" + shown_word(words[tool_at]) +
                    "' is no tool: hand, probe, forceps or scalpel");
    double numbers[5];
    for (int i = 0; i < 5; ++i) numbers[i] = number_of(words[i]);
    TrajectoryPoint point;
    point.time_s = numbers[0];
    point.position_mm = {numbers[1], numbers[2], numbers[3]};
    const double buttons = numbers[4];
    if (!std::isfinite(point.time_s) || !point.position_mm.allFinite())
      throw problem("a time or position that is not finite");
    if (!(buttons >= 0 && buttons <= 0xFFFF && buttons == std::floor(buttons)))
      throw problem("buttons " + words[4] + " is not a whole number in 0..65535");
    if (!points.empty() && !(point.time_s > points.back().time_s))
      throw problem("time " + std::to_string(point.time_s) + " s does not come after " +
                    std::to_string(points.back().time_s) + " s");
    if (with_orientation) {
      const Eigen::Quaterniond q(number_of(words[5]), number_of(words[6]), number_of(words[7]),
                                 number_of(words[8]));
      const double norm = q.norm();
      if (!std::isfinite(norm) || norm < 1e-6)
        throw problem("the orientation " + words[5] + " " + words[6] + " " + words[7] + " " +
                      words[8] + " is not a rotation (a quaternion of length 0 or not finite)");
      point.orientation = q.normalized();
    }
    if (!points.empty() && points.back().orientation.has_value() != with_orientation)
      throw problem(with_orientation ? "an orientation where the points before have none"
                                     : "no orientation where the points before have one");
    point.buttons = static_cast<std::uint32_t>(buttons);
    points.push_back(point);
    if (words.size() == tool_at + 1) read.tool_changes.push_back({point.time_s, words[tool_at]});
  }
  if (points.empty()) throw std::runtime_error(file.string() + ": no trajectory points");
  return read;
}

void save_trajectory(const std::filesystem::path& file,
                     const std::vector<TrajectoryPoint>& points) {
  std::ofstream out(file);
  out << "# time_s x_mm y_mm z_mm buttons [qw qx qy qz]\n" << std::setprecision(17);
  for (const TrajectoryPoint& p : points) {
    out << p.time_s << ' ' << p.position_mm.x() << ' ' << p.position_mm.y() << ' '
        << p.position_mm.z() << ' ' << p.buttons;
    if (p.orientation)
      out << ' ' << p.orientation->w() << ' ' << p.orientation->x() << ' ' << p.orientation->y()
          << ' ' << p.orientation->z();
    out << '\n';
  }
  if (!out) throw std::runtime_error("cannot write the trajectory file " + file.string());
}

std::vector<TrajectoryPoint> trajectory_of_frames(std::span<const ServoFrame> frames) {
  std::vector<TrajectoryPoint> points;
  points.reserve(frames.size());
  for (const ServoFrame& frame : frames) {
    const double time_s = frame.time_s - frames.front().time_s;
    if (!points.empty() && !(time_s > points.back().time_s)) continue;
    points.push_back(
        {time_s, frame.sample.position_mm, frame.sample.buttons, frame.sample.orientation});
  }
  return points;
}

TrajectoryDevice::TrajectoryDevice(std::string name, std::vector<TrajectoryPoint> points,
                                   DeviceLimits limits)
    : name_(std::move(name)), points_(std::move(points)), limits_(limits) {
  if (points_.empty()) throw std::invalid_argument(name_ + ": the trajectory is empty");
  for (std::size_t i = 1; i < points_.size(); ++i)
    if (!(points_[i].time_s > points_[i - 1].time_s))
      throw std::invalid_argument(name_ + ": trajectory times do not increase at point " +
                                  std::to_string(i));
}

DeviceStatus TrajectoryDevice::read(double time_s, DeviceSample& sample) {
  if (clock_s_) {
    const double now_s = clock_s_->load(std::memory_order_relaxed);
    if (clock_origin_s_ < 0.0) clock_origin_s_ = now_s;
    time_s = now_s - clock_origin_s_;
  }
  if (time_s < points_[cursor_].time_s) cursor_ = 0;  // the clock went back (a restart)
  while (cursor_ + 1 < points_.size() && points_[cursor_ + 1].time_s <= time_s) ++cursor_;
  const TrajectoryPoint& from = points_[cursor_];
  sample.buttons = from.buttons;
  sample.orientation = from.orientation;
  if (cursor_ + 1 == points_.size() || time_s <= from.time_s) {
    sample.position_mm = from.position_mm;
    sample.velocity_mm_per_s.setZero();
    return {};
  }
  const TrajectoryPoint& to = points_[cursor_ + 1];
  const double span_s = to.time_s - from.time_s;
  const double s = (time_s - from.time_s) / span_s;
  sample.position_mm = from.position_mm + s * (to.position_mm - from.position_mm);
  if (from.orientation && to.orientation)
    sample.orientation = from.orientation->slerp(s, *to.orientation);
  sample.velocity_mm_per_s = (to.position_mm - from.position_mm) / span_s;
  return {};
}

DeviceStatus TrajectoryDevice::write_force(const Eigen::Vector3d&) {
  return {};
}

}  // namespace liversim
