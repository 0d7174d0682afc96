#include "liversim/sessions/trace_metrics.h"

#include "liversim/engine/validation_message.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace liversim {
namespace {

// The part of one frame-to-frame interval of length `dt_s` where a signal going linearly from `a`
// to `b` is above `threshold`: its duration and the signal at its two ends. Linear, so the part
// is the whole interval, none of it, or one end up to the crossing.
struct PartAbove {
  double duration_s = 0.0;
  double first = 0.0, last = 0.0;
};

PartAbove part_above(double a, double b, double dt_s, double threshold) {
  if (a > threshold && b > threshold) return {dt_s, a, b};
  if (a <= threshold && b <= threshold) return {};
  if (a > threshold) return {dt_s * (a - threshold) / (a - b), a, threshold};  // falls through
  return {dt_s * (b - threshold) / (b - a), threshold, b};                     // rises through
}

// A frame the device reached by a jump (the mouse putting the tool down elsewhere), not a motion.
bool is_jump(const ServoFrame& frame) {
  return (frame.sample.buttons & kRepositioned) != 0;
}

// The scene distance the tip moved from one frame to the next: none for a jump, which is no path.
double scene_length_mm(const ServoFrame& from, const ServoFrame& to, double scale) {
  return is_jump(to) ? 0.0 : scale * (to.sample.position_mm - from.sample.position_mm).norm();
}

// The shortest text that reads back as the same double: two times that differ print differently.
std::string shortest(double value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

void check_setting(std::string_view name, double value) {
  if (!std::isfinite(value) || value < 0.0)
    throw std::invalid_argument("trace metrics: " +
                                out_of_range_message(name, value, "a finite value >= 0"));
}

void check_inputs(std::span<const ServoFrame> frames, std::span<const ToolInterval> tools,
                  const WorkspaceMapping& mapping, const TraceMetricSettings& settings) {
  if (const auto problem = validate(mapping))
    throw std::invalid_argument("trace metrics: " + *problem);
  check_setting("contact_force_n", settings.contact_force_n);
  check_setting("safe_force_n", settings.safe_force_n);
  check_setting("moving_speed_mm_per_s", settings.moving_speed_mm_per_s);
  check_setting("pause_s", settings.pause_s);

  for (std::size_t i = 0; i < frames.size(); ++i) {
    const ServoFrame& frame = frames[i];
    const char* bad = !std::isfinite(frame.time_s)                  ? "time_s"
                      : !frame.sample.position_mm.allFinite()       ? "position_mm"
                      : !frame.sample.velocity_mm_per_s.allFinite() ? "velocity_mm_per_s"
                      : !frame.force_n.allFinite()                  ? "force_n"
                                                                    : nullptr;
    std::ostringstream message;
    if (bad) {
      message << "servo frame " << i << ": " << bad << " is not finite (NaN or infinite)";
      throw std::invalid_argument(message.str());
    }
    if (i > 0 && !(frame.time_s > frames[i - 1].time_s)) {
      message << "servo frame " << i << ": time_s = " << shortest(frame.time_s)
              << " does not increase (frame " << i - 1 << " is at "
              << shortest(frames[i - 1].time_s) << ")";
      throw std::invalid_argument(message.str());
    }
  }
  for (std::size_t k = 0; k < tools.size(); ++k) {
    std::ostringstream message;
    if (!std::isfinite(tools[k].start_s)) {
      message << "tool interval " << k << ": start_s is not finite (NaN or infinite)";
      throw std::invalid_argument(message.str());
    }
    if (k > 0 && !(tools[k].start_s > tools[k - 1].start_s)) {
      message << "tool interval " << k << ": start_s = " << shortest(tools[k].start_s)
              << " does not increase (interval " << k - 1 << " starts at "
              << shortest(tools[k - 1].start_s) << ")";
      throw std::invalid_argument(message.str());
    }
  }
}

}  // namespace

TraceMetrics compute_trace_metrics(std::span<const ServoFrame> frames,
                                   std::span<const ToolInterval> tools,
                                   const WorkspaceMapping& mapping,
                                   const TraceMetricSettings& settings) {
  check_inputs(frames, tools, mapping, settings);
  TraceMetrics metrics;
  if (frames.empty()) return metrics;

  const double first_s = frames.front().time_s, last_s = frames.back().time_s;
  // Tools in use at some instant of [first_s, last_s] appear, even with nothing to count.
  for (std::size_t k = 0; k < tools.size(); ++k)
    if (tools[k].tool && tools[k].start_s <= last_s &&
        (k + 1 == tools.size() || tools[k + 1].start_s > first_s))
      metrics.per_tool.try_emplace(*tools[k].tool);

  // The force device = scale·Rᵀ·F_tissue, and a scene distance = scale × the device distance.
  auto tissue_force_n = [&](const ServoFrame& frame) {
    return frame.force_n.norm() / mapping.scale;
  };

  // Index of the tool in use (-1: before the first interval).
  std::ptrdiff_t tool_index = -1;
  auto advance_tool_to = [&](double time_s) {
    while (tool_index + 1 < std::ssize(tools) && tools[tool_index + 1].start_s <= time_s)
      ++tool_index;
  };

  double contact_s = 0.0, contact_force_integral_n_s = 0.0, contact_force_squared_integral = 0.0;
  std::optional<double> first_contact_s;
  bool moved = false;  // a movement has begun
  double last_motion_end_s = 0.0;

  // Economy of motion: each stroke's path and its start-to-end distance (scene mm). A stroke is a
  // movement, cut short by a jump (a reposition).
  struct Stroke {
    bool active = false;
    Eigen::Vector3d from_mm = Eigen::Vector3d::Zero();  // its start
    Eigen::Vector3d to_mm = Eigen::Vector3d::Zero();    // the end of its last moving interval
    double path_mm = 0.0;        // to the end of its last moving interval (scene)
    double still_path_mm = 0.0;  // drift since then (scene): its own if it moves on
  } stroke;
  double strokes_path_mm = 0.0, strokes_chord_mm = 0.0;
  const auto close_stroke = [&] {
    if (!stroke.active) return;
    strokes_path_mm += stroke.path_mm;
    strokes_chord_mm += mapping.scale * (stroke.to_mm - stroke.from_mm).norm();
    stroke.active = false;
  };

  metrics.peak_force_n = tissue_force_n(frames.front());
  if (metrics.peak_force_n > settings.contact_force_n) first_contact_s = first_s;

  for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
    const double start_s = frames[i].time_s, end_s = frames[i + 1].time_s;
    const double dt_s = end_s - start_s;
    const double force_a_n = tissue_force_n(frames[i]), force_b_n = tissue_force_n(frames[i + 1]);

    metrics.peak_force_n = std::max(metrics.peak_force_n, force_b_n);
    metrics.force_integral_n_s += 0.5 * dt_s * (force_a_n + force_b_n);
    metrics.peak_force_rate_n_per_s =
        std::max(metrics.peak_force_rate_n_per_s, std::abs(force_b_n - force_a_n) / dt_s);
    metrics.time_above_safe_force_s +=
        part_above(force_a_n, force_b_n, dt_s, settings.safe_force_n).duration_s;

    const PartAbove contact = part_above(force_a_n, force_b_n, dt_s, settings.contact_force_n);
    if (contact.duration_s > 0.0) {
      // Exact integrals of the linear force and of its square over the part in contact.
      contact_s += contact.duration_s;
      contact_force_integral_n_s += 0.5 * contact.duration_s * (contact.first + contact.last);
      contact_force_squared_integral +=
          contact.duration_s *
          (contact.first * contact.first + contact.first * contact.last +
           contact.last * contact.last) /
          3.0;
      if (!first_contact_s) first_contact_s = end_s - contact.duration_s;
    }

    const bool jump = is_jump(frames[i + 1]);
    const double length_mm = scene_length_mm(frames[i], frames[i + 1], mapping.scale);
    metrics.path_length_mm += length_mm;
    advance_tool_to(start_s);
    const std::ptrdiff_t tool_at_start = tool_index;
    // Tool changes inside the interval share its length by time (the tip moves at one speed).
    for (double from_s = start_s; from_s < end_s;) {
      const bool changes =
          tool_index + 1 < std::ssize(tools) && tools[tool_index + 1].start_s < end_s;
      const double until_s = changes ? tools[tool_index + 1].start_s : end_s;
      if (tool_index >= 0 && tools[tool_index].tool)
        metrics.per_tool[*tools[tool_index].tool].path_length_mm +=
            from_s == start_s && !changes ? length_mm : length_mm * (until_s - from_s) / dt_s;
      if (changes) ++tool_index;
      from_s = until_s;
    }

    if (length_mm / dt_s > settings.moving_speed_mm_per_s) {
      // The still time before it: idle when it lasted at least the pause.
      const double still_s = start_s - (moved ? last_motion_end_s : first_s);
      if (still_s >= settings.pause_s) metrics.idle_time_s += still_s;
      const bool new_movement = !moved || start_s - last_motion_end_s >= settings.pause_s;
      if (new_movement) {
        ++metrics.movements;
        // A movement counts for the tool in use when it began.
        if (tool_at_start >= 0 && tools[tool_at_start].tool)
          ++metrics.per_tool[*tools[tool_at_start].tool].movements;
      }
      if (new_movement || !stroke.active) {
        close_stroke();
        stroke = {true, frames[i].sample.position_mm, frames[i].sample.position_mm, 0.0, 0.0};
      }
      stroke.path_mm += stroke.still_path_mm + length_mm;
      stroke.still_path_mm = 0.0;
      stroke.to_mm = frames[i + 1].sample.position_mm;
      moved = true;
      last_motion_end_s = end_s;
    } else if (jump) {
      close_stroke();
    } else if (stroke.active) {
      stroke.still_path_mm += length_mm;
    }
  }
  close_stroke();
  if (strokes_chord_mm > 0.0) metrics.economy_of_motion = strokes_path_mm / strokes_chord_mm;
  if (const double still_s = last_s - (moved ? last_motion_end_s : first_s);
      still_s >= settings.pause_s)
    metrics.idle_time_s += still_s;
  if (first_contact_s) metrics.task_time_s = last_s - *first_contact_s;
  if (contact_s > 0.0) {
    metrics.mean_force_n = contact_force_integral_n_s / contact_s;
    metrics.rms_force_n = std::sqrt(contact_force_squared_integral / contact_s);
  }
  return metrics;
}

namespace {

// The spans of a hand's trace when it works: its tip moves, or it touches the tissue (the part of
// each interval in contact, crossings interpolated). In time order, touching spans merged.
std::vector<std::pair<double, double>> working_spans(const HandTrace& hand,
                                                     const TraceMetricSettings& settings) {
  std::vector<std::pair<double, double>> spans;
  const auto add = [&](double from_s, double to_s) {
    if (!(to_s > from_s)) return;
    if (!spans.empty() && from_s <= spans.back().second)
      spans.back().second = std::max(spans.back().second, to_s);
    else
      spans.emplace_back(from_s, to_s);
  };
  const std::span<const ServoFrame> frames = hand.frames;
  for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
    const double start_s = frames[i].time_s, end_s = frames[i + 1].time_s;
    const double dt_s = end_s - start_s;
    const double length_mm = scene_length_mm(frames[i], frames[i + 1], hand.mapping.scale);
    if (length_mm / dt_s > settings.moving_speed_mm_per_s) {
      add(start_s, end_s);
      continue;
    }
    const double a = frames[i].force_n.norm() / hand.mapping.scale;
    const double b = frames[i + 1].force_n.norm() / hand.mapping.scale;
    const PartAbove contact = part_above(a, b, dt_s, settings.contact_force_n);
    if (contact.duration_s <= 0.0) continue;
    if (a > settings.contact_force_n)
      add(start_s, start_s + contact.duration_s);  // in contact from the start
    else
      add(end_s - contact.duration_s, end_s);
  }
  return spans;
}

double total_s(const std::vector<std::pair<double, double>>& spans) {
  double total = 0.0;
  for (const auto& [from_s, to_s] : spans) total += to_s - from_s;
  return total;
}

}  // namespace

BimanualMetrics compute_bimanual_metrics(const HandTrace& right, const HandTrace& left,
                                         const TraceMetricSettings& settings) {
  for (const auto& [hand, name] : {std::pair{&right, "right hand"}, {&left, "left hand"}}) {
    try {
      check_inputs(hand->frames, {}, hand->mapping, settings);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string(name) + ": " + e.what());
    }
  }
  const auto right_spans = working_spans(right, settings);
  const auto left_spans = working_spans(left, settings);
  BimanualMetrics metrics;
  // The overlap of two ordered lists of disjoint spans.
  std::size_t r = 0, l = 0;
  while (r < right_spans.size() && l < left_spans.size()) {
    const double from_s = std::max(right_spans[r].first, left_spans[l].first);
    const double to_s = std::min(right_spans[r].second, left_spans[l].second);
    if (to_s > from_s) metrics.both_working_s += to_s - from_s;
    if (right_spans[r].second < left_spans[l].second)
      ++r;
    else
      ++l;
  }
  metrics.either_working_s = total_s(right_spans) + total_s(left_spans) - metrics.both_working_s;
  if (metrics.either_working_s > 0.0)
    metrics.both_working_fraction = metrics.both_working_s / metrics.either_working_s;
  return metrics;
}

}  // namespace liversim
