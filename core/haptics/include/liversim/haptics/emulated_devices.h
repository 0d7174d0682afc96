#pragma once
// The devices that need no hardware: the mouse and keyboard, a scripted trajectory, and the replay
// of a logged session. They are product features (the default without a Phantom, the CLI and the
// instructor's replay) and what the tests drive the force path with.

#include "liversim/haptics/haptic_device.h"
#include "liversim/haptics/servo_loop.h"
#include "liversim/haptics/triple_buffer.h"

#include <array>
#include <atomic>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace liversim {

// The mouse and keyboard: the workstation sets the position (device mm) and buttons from mouse
// drags, modifiers and the wheel; the servo reads the newest, and takes the velocity from the
// change. The force written is kept (the mouse cannot push back) so that it can be shown.
class ManualDevice final : public HapticDevice {
 public:
  std::string name() const override { return "Mouse and keyboard"; }
  DeviceLimits limits() const override { return limits_; }
  DeviceStatus read(double time_s, DeviceSample& sample) override;
  DeviceStatus write_force(const Eigen::Vector3d& force_n) override;

  // UI thread. `set` moves the device there (its velocity is the change over the servo's ticks);
  // `place` puts it there at once (a press where the mouse is, not a motion: zero velocity, and
  // the first sample there marked kRepositioned).
  void set(const Eigen::Vector3d& position_mm, std::uint32_t buttons);
  void place(const Eigen::Vector3d& position_mm, std::uint32_t buttons);
  Eigen::Vector3d last_force_n();

 private:
  struct Input {
    Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();
    std::uint32_t buttons = 0;
    std::uint64_t placement = 0;  // counts place() calls
  };
  DeviceLimits limits_;  // the Omni's: the mouse pushes nothing back
  TripleBuffer<Input> input_{Input{}};
  TripleBuffer<Eigen::Vector3d> force_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d previous_mm_ = Eigen::Vector3d::Zero();
  double previous_s_ = -1.0;
  std::uint64_t placements_ = 0;      // UI thread
  std::uint64_t read_placement_ = 0;  // servo thread
};

// One point of a trajectory: where the device is at a time, which buttons are down, and the
// stylus's orientation if the trajectory gives it (DeviceSample::orientation).
struct TrajectoryPoint {
  TrajectoryPoint() = default;
  TrajectoryPoint(double time_s_in, const Eigen::Vector3d& position_mm_in, std::uint32_t buttons_in,
                  const std::optional<Eigen::Quaterniond>& orientation_in = std::nullopt)
      : time_s(time_s_in),
        position_mm(position_mm_in),
        buttons(buttons_in),
        orientation(orientation_in) {}
  double time_s = 0.0;
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();
  std::uint32_t buttons = 0;
  std::optional<Eigen::Quaterniond> orientation;
};

// What the hand holds from a time on, as a trajectory file says: one of kTrajectoryTools.
struct TrajectoryToolChange {
  double time_s = 0.0;
  std::string tool;
};
inline constexpr std::array<std::string_view, 4> kTrajectoryTools = {"hand", "probe", "forceps",
                                                                     "scalpel"};
struct TrajectoryFile {
  std::vector<TrajectoryPoint> points;
  std::vector<TrajectoryToolChange> tool_changes;  // in time order; empty: the tool is not set
};

// A trajectory file: one point per line, `time_s x_mm y_mm z_mm buttons [qw qx qy qz] [tool]`,
// whitespace-separated, times strictly increasing; `#` starts a comment. The optional quaternion
// is the stylus's orientation in the device frame (normalised as read); a file gives it at every
// point or at none. The optional tool (hand, probe, forceps or scalpel) is what the hand holds
// from that point on, which the one playing the trajectory puts in it (liversim-cli record).
// Throws std::runtime_error naming the file, the line and what is wrong.
TrajectoryFile read_trajectory_file(const std::filesystem::path& file);
// Its points alone.
std::vector<TrajectoryPoint> load_trajectory(const std::filesystem::path& file);
void save_trajectory(const std::filesystem::path& file, const std::vector<TrajectoryPoint>& points);

// The device input logged with a session (servo frames), as a trajectory starting at time 0:
// positions and buttons at the frames' own times, so a TrajectoryDevice replays it at its original
// rate. Frames whose time does not increase are skipped.
std::vector<TrajectoryPoint> trajectory_of_frames(std::span<const ServoFrame> frames);

// Plays a trajectory on the servo clock: positions interpolated linearly between points (and
// orientations spherically), the velocity the slope there, the buttons of the point before. Before
// the first point it stays at the first, after the last at the last. A scripted device follows a
// trajectory file; a replay device follows the device input logged with a session, at its original
// rate.
class TrajectoryDevice final : public HapticDevice {
 public:
  // Throws std::invalid_argument for an empty trajectory or times that do not increase.
  TrajectoryDevice(std::string name, std::vector<TrajectoryPoint> points, DeviceLimits limits = {});
  std::string name() const override { return name_; }
  DeviceLimits limits() const override { return limits_; }
  DeviceStatus read(double time_s, DeviceSample& sample) override;
  DeviceStatus write_force(const Eigen::Vector3d& force_n) override;

  double duration_s() const { return points_.back().time_s; }
  const std::vector<TrajectoryPoint>& points() const { return points_; }

  // Plays on `clock_s` instead of the servo's clock, from its value at the first read: a
  // simulation's time (RealtimeSimulation::simulated_time_s), so that the script waits for a
  // simulation that falls behind instead of running ahead of it. What a scripted run that must not
  // depend on the machine's load plays on (tests wait on simulated time). Set before the servo
  // starts; null: the servo's clock again. The clock is only read (atomically): the servo path
  // stays lock-free.
  void play_on(const std::atomic<double>* clock_s) {
    clock_s_ = clock_s;
    clock_origin_s_ = -1.0;
  }

 private:
  std::string name_;
  std::vector<TrajectoryPoint> points_;
  DeviceLimits limits_;
  const std::atomic<double>* clock_s_ = nullptr;
  double clock_origin_s_ = -1.0;  // < 0: not read yet
  std::size_t cursor_ = 0;        // the segment of the last read: reads move forward, so no search
};

}  // namespace liversim
