#pragma once
// The mouse on the liver: the hand's grab (a drag pulls the tissue under the cursor through
// springs) and, with a tool chosen, the tool the mouse holds through the station's ManualDevice
// (put on the liver where it presses, moved while it is held, lifted away on release). The camera
// takes what it does not.

#include "render/liver_scene.h"

#include "liversim/interaction/grab.h"
#include "liversim/interaction/tools.h"
#include "liversim/simulation/realtime_simulation.h"
#include "liversim/station/workstation.h"

#include <Eigen/Geometry>

#include <QPoint>
#include <Qt>

#include <functional>
#include <optional>
#include <vector>

namespace liversim {

class MouseToolControl {
 public:
  // `view_axes`: device axes → scene for the current view (x right, y up, z toward the user).
  MouseToolControl(Workstation& station, std::function<LiverScene&()> scene,
                   std::function<Eigen::Quaterniond()> view_axes);

  // A press on the viewport: true when the mouse takes it (the hand grabs, a tool is put down),
  // false when the camera should. `tool`: the Tool panel's (none: the hand).
  bool press(QPoint display, Qt::MouseButton button, Qt::KeyboardModifiers modifiers,
             std::optional<ToolKind> tool);
  void move(QPoint display, Qt::KeyboardModifiers modifiers);
  // Pushes the tool the mouse holds in along its shaft by `in_m` (negative: draws it back); false
  // when it holds none.
  bool pushIn(double in_m);
  void release(Qt::MouseButton button);
  // Lets go of the grab and the tool (the scene is replaced, a device takes over, the tool
  // changed).
  void letGo();
  void endGrab();
  void endTool();

  const Grab* grab() const { return grab_ ? &*grab_ : nullptr; }
  const std::optional<Tool>& tool() const { return tool_; }
  // The hand's pull on the tissue now, while it grabs.
  std::optional<Eigen::Vector3d> grabForce_n(const NodeArray& position_m) const;
  // What the mouse holds as the device's tool: the tool while pressed, else none.
  std::optional<DeviceToolSettings> deviceTool() const;

  // Spring stiffness of a grab and the radius of tissue it holds.
  static constexpr double kGrabStiffnessNPerM = 300.0;
  static constexpr double kGrabRadiusM = 0.02;
  // A release lifts the tool this far up its shaft.
  static constexpr double kLiftM = 0.03;
  // One notch of the wheel pushes a held tool in (or draws it back) this far.
  static constexpr double kWheelPushM = 0.001;
  // The scalpel is put on with its blade's heel this far up its shaft from the surface.
  static constexpr double kScalpelHeelAboveM = 0.004;

 private:
  bool beginTool(ToolKind kind, QPoint display);

  Workstation& station_;
  std::function<LiverScene&()> scene_;
  std::function<Eigen::Quaterniond()> viewAxes_;
  std::optional<Grab> grab_;
  Eigen::Vector3d handle_m_ = Eigen::Vector3d::Zero();
  std::vector<NodeSpring> springs_;
  std::optional<Tool> tool_;
  Eigen::Vector3d toolPoint_m_ = Eigen::Vector3d::Zero();  // where the mouse holds the tool
};

}  // namespace liversim
