#include "mouse_tool_control.h"

#include "liversim/haptics/haptics.h"

namespace liversim {

MouseToolControl::MouseToolControl(Workstation& station, std::function<LiverScene&()> scene,
                                   std::function<Eigen::Quaterniond()> view_axes)
    : station_(station), scene_(std::move(scene)), viewAxes_(std::move(view_axes)) {}

bool MouseToolControl::press(QPoint pos, Qt::MouseButton button, Qt::KeyboardModifiers modifiers,
                             std::optional<ToolKind> tool) {
  // While the tissue is held, other buttons must not move the camera under the handle.
  if (grab_ || tool_) return true;
  if (button != Qt::LeftButton || modifiers != Qt::NoModifier) return false;
  if (tool) {
    if (!station_.mouse()) return false;  // a device holds the tool: the mouse turns the view
    return beginTool(*tool, pos);
  }
  LiverScene& scene = scene_();
  const auto hit = scene.pick(pos.x(), pos.y());
  if (!hit) return false;  // background: the camera takes the drag
  const SimulationSnapshot& snapshot = station_.simulation().snapshot();
  grab_ = grab_surface(scene.surface(), snapshot.position_m, snapshot.model->lumped_mass_kg,
                       hit->point_m, kGrabRadiusM, kGrabStiffnessNPerM);
  handle_m_ = hit->point_m;
  scene.show_grab_marker(handle_m_);
  grab_springs(*grab_, handle_m_, springs_);
  station_.set_hand_springs(springs_);
  return true;
}

void MouseToolControl::move(QPoint pos, Qt::KeyboardModifiers modifiers) {
  LiverScene& scene = scene_();
  if (grab_) {
    handle_m_ = scene.display_to_world(pos.x(), pos.y(), handle_m_);
    scene.show_grab_marker(handle_m_);
    grab_springs(*grab_, handle_m_, springs_);
    station_.set_hand_springs(springs_);
  }
  if (tool_ && station_.mouse()) {
    // Dragging moves the tool in the view plane; with Shift, up and down the screen move it along
    // its shaft (down pushes it in).
    const Eigen::Vector3d point = scene.display_to_world(pos.x(), pos.y(), toolPoint_m_);
    Eigen::Vector3d step = point - toolPoint_m_;
    if (modifiers & Qt::ShiftModifier) {
      const Eigen::Vector2d from = scene.world_to_display(toolPoint_m_);
      const double up = pos.y() > from.y() ? 1.0 : -1.0;  // display y grows upward
      pushIn(-up * step.norm());
      return;
    }
    tool_->pose.origin_m += step;
    toolPoint_m_ += step;
    station_.mouse()->set(tool_->pose.origin_m * 1e3, Workstation::kMouseActionButton);
  }
}

bool MouseToolControl::pushIn(double in_m) {
  if (!tool_ || !station_.mouse()) return false;
  const Eigen::Vector3d shaft = tool_->pose.orientation * Eigen::Vector3d::UnitZ();  // outward
  tool_->pose.origin_m -= in_m * shaft;
  toolPoint_m_ -= in_m * shaft;
  station_.mouse()->set(tool_->pose.origin_m * 1e3, Workstation::kMouseActionButton);
  return true;
}

void MouseToolControl::release(Qt::MouseButton button) {
  if (button != Qt::LeftButton) return;
  if (grab_) endGrab();
  if (tool_) endTool();
}

void MouseToolControl::letGo() {
  if (grab_) endGrab();
  if (tool_) endTool();
}

void MouseToolControl::endGrab() {
  grab_.reset();
  station_.clear_hand_springs();
  scene_().show_grab_marker(std::nullopt);
}

// The mouse is a device like the others (ManualDevice, through the servo, recorded): a press puts
// the tool on the liver where the mouse is, its shaft toward the viewer and tilted up by 35° (as a
// laparoscopic instrument comes in through a port, and so that it shows), with the action button
// down: the probe's ball on the surface, the forceps' jaws closed on it, the blade's tip touching
// it and armed. The mouse's millimetres are the scene's.
bool MouseToolControl::beginTool(ToolKind kind, QPoint pos) {
  const auto hit = scene_().pick(pos.x(), pos.y());
  if (!hit) return false;  // background: the camera takes the drag
  Tool tool;
  tool.kind = kind;
  tool.jaw_opening = 0.0;
  tool.pose.orientation = tool_orientation_from_view(viewAxes_());
  const Eigen::Vector3d shaft = tool.pose.orientation * Eigen::Vector3d::UnitZ();
  switch (kind) {
    case ToolKind::probe:
      tool.pose.origin_m = hit->point_m + tool.geometry.probe_tip_radius_m * shaft;
      break;
    case ToolKind::forceps:
      tool.pose.origin_m = hit->point_m - (forceps_grasp_point_m(tool) - tool.pose.origin_m);
      break;
    case ToolKind::scalpel:
      // The blade goes in where you press, its heel just above the surface so that drawing it
      // along keeps the edge through the tissue's top: it cuts once the tissue gives way.
      tool.pose.origin_m = hit->point_m + kScalpelHeelAboveM * shaft;
      break;
  }
  tool_ = tool;
  toolPoint_m_ = hit->point_m;
  station_.mouse()->place(tool.pose.origin_m * 1e3, Workstation::kMouseActionButton);
  // After the placement, so that the frames of the tool's interval are all where it is put. A
  // session of the mouse begins when it first takes a tool to the liver (and restarts the
  // simulation from rest: the device tool is set on the simulation that runs after).
  if (!station_.recording_session())
    station_.begin_recording();
  else
    station_.record_tool_choice();
  station_.device_tool_changed(station_.servo()->now_s());
  return true;
}

// The release lets go (the action button up) and takes the tool out of the scene; the device's
// point is lifted along the shaft, so that a replay of the session's device input, which keeps
// the tool in the scene, does not leave it resting on the liver.
void MouseToolControl::endTool() {
  const Eigen::Vector3d shaft = tool_->pose.orientation * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d lifted_m = tool_->pose.origin_m + kLiftM * shaft;
  tool_.reset();
  station_.record_tool_choice();  // before the lift, which is no motion of the tool in use
  if (ManualDevice* mouse = station_.mouse()) mouse->place(lifted_m * 1e3, 0);
  station_.device_tool_changed();  // the forceps let go as they leave
}

std::optional<Eigen::Vector3d> MouseToolControl::grabForce_n(const NodeArray& position_m) const {
  if (!grab_) return std::nullopt;
  return grab_reaction_force_n(*grab_, handle_m_, position_m);
}

std::optional<DeviceToolSettings> MouseToolControl::deviceTool() const {
  if (!tool_) return std::nullopt;  // the mouse holds a tool only while pressed
  DeviceToolSettings settings;
  settings.kind = tool_->kind;
  settings.orientation = tool_->pose.orientation;
  settings.action_buttons = Workstation::kMouseActionButton;
  return settings;
}

}  // namespace liversim
