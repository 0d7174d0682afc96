#include "liversim/sessions/session_store.h"

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <sstream>

namespace liversim {

namespace {

constexpr std::array<std::string_view, 13> kEventNames = {"grasp",
                                                          "release",
                                                          "cut",
                                                          "excessive_force",
                                                          "lesion_breach",
                                                          "simulation_recovery",
                                                          "device_fault",
                                                          "tool_selected",
                                                          "lesion_marked",
                                                          "integrator_changed",
                                                          "material_changed",
                                                          "gravity_changed",
                                                          "specimen_removed"};

// Layout 1: "LSF1", the frame count (u32), then one column per quantity, frame by frame: time,
// position x, y, z, velocity x, y, z, force x, y, z (IEEE doubles), buttons (u32). Columns keep
// like values together, which a compressing layout would want. Layout 2: "LSF2", the same with
// four more double columns before the buttons, the stylus's orientation w, x, y, z (NaN: the
// device gave none).
constexpr std::array<char, 4> kMagicV1 = {'L', 'S', 'F', '1'};
constexpr std::array<char, 4> kMagic = {'L', 'S', 'F', '2'};
constexpr std::size_t kHeaderBytes = 8;
constexpr std::size_t kDoublesV1 = 10, kDoubles = 14;

void put_u32(std::uint8_t* out, std::uint32_t value) {
  for (int b = 0; b < 4; ++b) out[b] = static_cast<std::uint8_t>(value >> (8 * b));
}
void put_f64(std::uint8_t* out, double value) {
  const auto bits = std::bit_cast<std::uint64_t>(value);
  for (int b = 0; b < 8; ++b) out[b] = static_cast<std::uint8_t>(bits >> (8 * b));
}
std::uint32_t get_u32(const std::uint8_t* in) {
  std::uint32_t value = 0;
  for (int b = 0; b < 4; ++b) value |= static_cast<std::uint32_t>(in[b]) << (8 * b);
  return value;
}
double get_f64(const std::uint8_t* in) {
  std::uint64_t bits = 0;
  for (int b = 0; b < 8; ++b) bits |= static_cast<std::uint64_t>(in[b]) << (8 * b);
  return std::bit_cast<double>(bits);
}

// The ten double columns of a frame, in layout order.
template <typename Frame, typename Visit>
void for_each_double(Frame& frame, Visit&& visit) {
  visit(frame.time_s);
  for (int k = 0; k < 3; ++k) visit(frame.sample.position_mm[k]);
  for (int k = 0; k < 3; ++k) visit(frame.sample.velocity_mm_per_s[k]);
  for (int k = 0; k < 3; ++k) visit(frame.force_n[k]);
}

// The orientation's columns: w, x, y, z, NaN without one.
std::array<double, 4> orientation_columns(const DeviceSample& sample) {
  if (!sample.orientation) return {NAN, NAN, NAN, NAN};
  const Eigen::Quaterniond& q = *sample.orientation;
  return {q.w(), q.x(), q.y(), q.z()};
}

}  // namespace

std::string_view session_event_name(SessionEventKind kind) {
  return kEventNames[static_cast<std::size_t>(kind)];
}

std::optional<SessionEventKind> session_event_kind(std::string_view name) {
  for (std::size_t k = 0; k < kEventNames.size(); ++k)
    if (kEventNames[k] == name) return static_cast<SessionEventKind>(k);
  return std::nullopt;
}

std::string_view session_status_name(SessionStatus status) {
  switch (status) {
    case SessionStatus::recording:
      return "recording";
    case SessionStatus::complete:
      return "complete";
    case SessionStatus::incomplete:
      return "incomplete";
  }
  return "incomplete";
}

SessionServoFigures servo_figures(const ServoStats& stats, std::uint64_t dropped_frames) {
  SessionServoFigures f;
  f.ticks = stats.ticks;
  f.rate_hz = stats.rate_hz();
  f.period_p50_ms = stats.period_percentile_s(0.5) * 1e3;
  f.period_p99_ms = stats.period_percentile_s(0.99) * 1e3;
  f.period_max_ms = stats.max_period_s * 1e3;
  f.missed_deadlines = stats.missed_deadlines;
  f.force_clamps = stats.force_clamps;
  f.stiffness_clamps = stats.stiffness_clamps;
  f.rate_limited = stats.rate_limited;
  f.watchdog_trips = stats.watchdog_trips;
  f.device_faults = stats.device_faults;
  f.dropped_frames = dropped_frames;
  return f;
}

std::vector<ToolInterval> tool_intervals(std::span<const SessionEvent> events, Hand hand) {
  std::vector<ToolInterval> intervals;
  for (const SessionEvent& event : events) {
    if (event.kind != SessionEventKind::tool_selected || event.hand != hand) continue;
    // The hand, or a name no tool has: no tool.
    const ToolInterval interval{event.time_s, tool_kind(event.detail)};
    // Two choices at one instant (the servo clock's resolution): the later one holds.
    if (!intervals.empty() && !(interval.start_s > intervals.back().start_s))
      intervals.back() = interval;
    else
      intervals.push_back(interval);
  }
  return intervals;
}

std::string mark_detail(const Eigen::Vector3d& rest_point_m) {
  std::ostringstream text;
  text.precision(17);
  text << rest_point_m.x() * 1e3 << ' ' << rest_point_m.y() * 1e3 << ' ' << rest_point_m.z() * 1e3;
  return text.str();
}

std::vector<Eigen::Vector3d> lesion_marks(std::span<const SessionEvent> events) {
  std::vector<Eigen::Vector3d> marks;
  for (const SessionEvent& event : events) {
    if (event.kind != SessionEventKind::lesion_marked) continue;
    std::istringstream text(event.detail);
    Eigen::Vector3d mm;
    if (text >> mm.x() >> mm.y() >> mm.z() && mm.allFinite()) marks.push_back(mm * 1e-3);
  }
  return marks;
}

std::vector<MetricValue> trace_metric_values(const TraceMetrics& m) {
  std::vector<MetricValue> values{{"task_time_s", m.task_time_s},
                                  {"path_length_mm", m.path_length_mm},
                                  {"movements", static_cast<double>(m.movements)},
                                  {"idle_time_s", m.idle_time_s},
                                  {"peak_force_n", m.peak_force_n},
                                  {"mean_force_n", m.mean_force_n},
                                  {"rms_force_n", m.rms_force_n},
                                  {"time_above_safe_force_s", m.time_above_safe_force_s},
                                  {"force_integral_n_s", m.force_integral_n_s},
                                  {"peak_force_rate_n_per_s", m.peak_force_rate_n_per_s}};
  // Measured only when the tool moved.
  if (m.economy_of_motion) values.push_back({"economy_of_motion", *m.economy_of_motion});
  return values;
}

std::vector<MetricValue> left_hand_metric_values(const TraceMetrics& m) {
  std::vector<MetricValue> values;
  for (MetricValue& value : trace_metric_values(m)) {
    if (value.name == "task_time_s") continue;  // the session's, from its first contact
    value.name = "left_" + value.name;
    values.push_back(std::move(value));
  }
  return values;
}

std::vector<std::uint8_t> encode_frame_chunk(std::span<const ServoFrame> frames) {
  const std::size_t n = frames.size();
  std::vector<std::uint8_t> bytes(kHeaderBytes + n * (kDoubles * 8 + 4));
  std::memcpy(bytes.data(), kMagic.data(), kMagic.size());
  put_u32(bytes.data() + 4, static_cast<std::uint32_t>(n));
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t column = 0;
    auto put = [&](double value) {
      put_f64(bytes.data() + kHeaderBytes + (column * n + i) * 8, value);
      ++column;
    };
    for_each_double(frames[i], put);
    for (double value : orientation_columns(frames[i].sample)) put(value);
    put_u32(bytes.data() + kHeaderBytes + kDoubles * 8 * n + i * 4, frames[i].sample.buttons);
  }
  return bytes;
}

std::vector<ServoFrame> decode_frame_chunk(std::span<const std::uint8_t> bytes) {
  const bool v1 = bytes.size() >= kHeaderBytes &&
                  std::memcmp(bytes.data(), kMagicV1.data(), kMagicV1.size()) == 0;
  if (bytes.size() < kHeaderBytes ||
      (!v1 && std::memcmp(bytes.data(), kMagic.data(), kMagic.size()) != 0))
    throw StorageError(
        "a frame chunk does not start with the layout-1 or layout-2 mark (\"LSF1\", \"LSF2\")");
  const std::size_t doubles = v1 ? kDoublesV1 : kDoubles;
  const std::size_t n = get_u32(bytes.data() + 4);
  const std::size_t expected = kHeaderBytes + n * (doubles * 8 + 4);
  if (bytes.size() != expected)
    throw StorageError("a frame chunk of " + std::to_string(n) + " frames has " +
                       std::to_string(bytes.size()) + " bytes, expected " +
                       std::to_string(expected));
  std::vector<ServoFrame> frames(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t column = 0;
    auto get = [&]() {
      const double value = get_f64(bytes.data() + kHeaderBytes + (column * n + i) * 8);
      ++column;
      return value;
    };
    for_each_double(frames[i], [&](double& value) { value = get(); });
    if (!v1) {
      const double w = get(), x = get(), y = get(), z = get();
      if (!std::isnan(w)) frames[i].sample.orientation = Eigen::Quaterniond(w, x, y, z);
    }
    frames[i].sample.buttons = get_u32(bytes.data() + kHeaderBytes + doubles * 8 * n + i * 4);
  }
  return frames;
}

namespace {

// Input chunk layout 1: "LSI1", the input count (u32), then one record per input, little-endian:
// its kind (u8: 0 tool, 1 springs, 2 cycle) and
// - tool: present (u8); if 1: tool kind (u8), blade armed (u8) and 16 doubles: origin x, y, z (m),
//   orientation w, x, y, z, jaw opening, then ToolGeometry's 8 lengths in declaration order;
// - springs: count (u32), then per spring: node (i32), anchor x, y, z (m), stiffness (N/m),
//   damping (N·s/m) as doubles;
// - cycle: steps (u32), energy books closed (u8), servo time (double, s).
constexpr std::array<char, 4> kInputMagic = {'L', 'S', 'I', '1'};

template <typename Visit>
void for_each_tool_double(Tool& tool, Visit&& visit) {
  ToolGeometry& g = tool.geometry;
  for (double* value :
       {&tool.pose.origin_m.x(), &tool.pose.origin_m.y(), &tool.pose.origin_m.z(),
        &tool.pose.orientation.w(), &tool.pose.orientation.x(), &tool.pose.orientation.y(),
        &tool.pose.orientation.z(), &tool.jaw_opening, &g.shaft_radius_m, &g.shaft_length_m,
        &g.probe_tip_radius_m, &g.jaw_length_m, &g.jaw_radius_m, &g.max_jaw_angle_rad,
        &g.blade_length_m, &g.blade_half_thickness_m})
    visit(*value);
}

class ByteWriter {
 public:
  void u8(std::uint8_t value) { bytes_.push_back(value); }
  // Through a local copy rather than resize-then-write, which GCC 12 misreads as an overflow.
  void u32(std::uint32_t value) {
    std::uint8_t raw[4];
    put_u32(raw, value);
    bytes_.insert(bytes_.end(), raw, raw + 4);
  }
  void f64(double value) {
    std::uint8_t raw[8];
    put_f64(raw, value);
    bytes_.insert(bytes_.end(), raw, raw + 8);
  }
  std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
};

// Reads with bounds checks: running out names the input being read.
class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  std::uint8_t u8() { return *take(1); }
  std::uint32_t u32() { return get_u32(take(4)); }
  double f64() { return get_f64(take(8)); }
  std::size_t remaining() const { return bytes_.size() - at_; }
  std::size_t input = 0;  // the input being read, for messages

 private:
  const std::uint8_t* take(std::size_t n) {
    if (remaining() < n)
      throw StorageError("an input chunk ends inside input " + std::to_string(input));
    at_ += n;
    return bytes_.data() + at_ - n;
  }
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
};

}  // namespace

namespace {
constexpr std::uint8_t kLeftHandToolInput = 4;
}  // namespace

std::vector<std::uint8_t> encode_input_chunk(std::span<const SimulationInput> inputs) {
  ByteWriter out;
  for (char c : kInputMagic) out.u8(static_cast<std::uint8_t>(c));
  out.u32(static_cast<std::uint32_t>(inputs.size()));
  for (const SimulationInput& input : inputs) {
    // A tool of the left hand is kind 4, laid out as the right hand's (kind 0): files written
    // before there were two hands read as they were.
    out.u8(input.kind == SimulationInput::Kind::tool && input.hand == Hand::left
               ? kLeftHandToolInput
               : static_cast<std::uint8_t>(input.kind));
    switch (input.kind) {
      case SimulationInput::Kind::tool: {
        out.u8(input.tool ? 1 : 0);
        if (!input.tool) break;
        Tool tool = *input.tool;
        out.u8(static_cast<std::uint8_t>(tool.kind));
        out.u8(tool.blade_armed ? 1 : 0);
        for_each_tool_double(tool, [&](double value) { out.f64(value); });
        break;
      }
      case SimulationInput::Kind::springs:
        out.u32(static_cast<std::uint32_t>(input.springs.size()));
        for (const NodeSpring& spring : input.springs) {
          out.u32(static_cast<std::uint32_t>(spring.node));
          for (double value : {spring.anchor_m.x(), spring.anchor_m.y(), spring.anchor_m.z(),
                               spring.stiffness_n_per_m, spring.damping_n_s_per_m})
            out.f64(value);
        }
        break;
      case SimulationInput::Kind::cycle:
        out.u32(static_cast<std::uint32_t>(input.steps));
        out.u8(input.check_energy ? 1 : 0);
        out.f64(input.servo_time_s);
        break;
      case SimulationInput::Kind::take_out_specimens:
        out.u8(0);  // which: every free body (the only choice so far)
        break;
    }
  }
  return std::move(out.bytes());
}

std::vector<SimulationInput> decode_input_chunk(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kInputMagic.data(), kInputMagic.size()) != 0)
    throw StorageError("an input chunk does not start with the layout-1 mark \"LSI1\"");
  ByteReader in(bytes.subspan(4));
  const std::uint32_t count = in.u32();
  // Every input takes at least 2 bytes: a count beyond that is a damaged header.
  if (count > in.remaining() / 2)
    throw StorageError("an input chunk claims " + std::to_string(count) + " inputs in " +
                       std::to_string(bytes.size()) + " bytes");
  std::vector<SimulationInput> inputs(count);
  for (SimulationInput& input : inputs) {
    const std::uint8_t kind = in.u8();
    switch (kind) {
      case 0:
      case kLeftHandToolInput: {
        input.kind = SimulationInput::Kind::tool;
        input.hand = kind == kLeftHandToolInput ? Hand::left : Hand::right;
        if (in.u8() == 0) break;
        Tool tool;
        const std::uint8_t tool_kind = in.u8();
        if (tool_kind >= kToolKinds.size())
          throw StorageError("input " + std::to_string(in.input) + " of an input chunk has tool " +
                             std::to_string(tool_kind) + ", which is no tool");
        tool.kind = static_cast<ToolKind>(tool_kind);
        tool.blade_armed = in.u8() != 0;
        for_each_tool_double(tool, [&](double& value) { value = in.f64(); });
        input.tool = tool;
        break;
      }
      case 1: {
        input.kind = SimulationInput::Kind::springs;
        const std::uint32_t springs = in.u32();
        if (springs > in.remaining() / 44)
          throw StorageError("an input chunk ends inside input " + std::to_string(in.input));
        input.springs.resize(springs);
        for (NodeSpring& spring : input.springs) {
          spring.node = static_cast<NodeIndex>(in.u32());
          for (double* value : {&spring.anchor_m.x(), &spring.anchor_m.y(), &spring.anchor_m.z(),
                                &spring.stiffness_n_per_m, &spring.damping_n_s_per_m})
            *value = in.f64();
        }
        break;
      }
      case 2:
        input.kind = SimulationInput::Kind::cycle;
        input.steps = static_cast<int>(in.u32());
        // The live loop's cap is far below this; more would be a damaged record.
        if (input.steps < 1 || input.steps > 1'000'000)
          throw StorageError("input " + std::to_string(in.input) +
                             " of an input chunk is a cycle of " + std::to_string(input.steps) +
                             " steps");
        input.check_energy = in.u8() != 0;
        input.servo_time_s = in.f64();
        break;
      case 3:
        input.kind = SimulationInput::Kind::take_out_specimens;
        if (const std::uint8_t which = in.u8(); which != 0)
          throw StorageError("input " + std::to_string(in.input) +
                             " of an input chunk takes out specimens " + std::to_string(which) +
                             ", which is none this version knows (0: every free body)");
        break;
      default:
        throw StorageError("input " + std::to_string(in.input) + " of an input chunk has kind " +
                           std::to_string(kind) +
                           ", which is none this version knows (0 tool, 1 springs, 2 cycle, 3 "
                           "specimens taken out, 4 left hand's tool)");
    }
    ++in.input;
  }
  if (in.remaining() != 0)
    throw StorageError("an input chunk has " + std::to_string(in.remaining()) +
                       " bytes after its last input");
  return inputs;
}

}  // namespace liversim
