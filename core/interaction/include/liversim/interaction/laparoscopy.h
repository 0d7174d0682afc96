#pragma once
// The laparoscopic fulcrum (issue 43, item 4): an instrument is a straight rigid shaft that passes
// through a trocar port in the abdominal wall and pivots about it. The hand holds the handle
// outside; the tip moves inside, opposite to the handle across the shaft and by the ratio of the
// length inside to the length outside, which changes with the insertion depth. A force on the tip
// is felt at the handle through the same lever. docs/laparoscopy.md derives both.
//
// Built so far: the mapping and its force reflection, tested against hand-computed cases. Not
// built yet: ports in scenarios, the device driving a handle through them, the laparoscope's view.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <optional>
#include <string>

namespace liversim {

// A port in the abdominal wall (scene, m): instruments pass through `position_m` within
// `cone_half_angle_rad` of `axis` (a unit vector pointing into the body).
struct TrocarPort {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = -Eigen::Vector3d::UnitZ();
  double cone_half_angle_rad = 0.7;  // about 40°
};

// The problem with a port or an instrument length, if any (a message naming the value).
std::optional<std::string> validate(const TrocarPort& port, double instrument_length_m);

// An instrument through its port, for a handle point.
struct FulcrumPose {
  Eigen::Vector3d handle_m;  // the handle, moved onto the cone when it was outside it
  Eigen::Vector3d tip_m;
  Eigen::Vector3d shaft;       // unit, from the handle through the port toward the tip
  double outside_m = 0.0;      // handle to port
  double inside_m = 0.0;       // port to tip: the insertion depth (0: withdrawn to the port)
  bool at_cone_limit = false;  // the handle asked for lay outside the port's cone
  bool withdrawn = false;      // the handle is an instrument's length or more from the port
  // The tool's orientation: its working end (the tool frame's −z) along the shaft.
  Eigen::Quaterniond orientation() const;
};

// Where an instrument of `length_m` (handle to tip) is when its handle is at `handle_m`: the
// shaft runs from the handle through the port, the tip `length_m − |handle − port|` past it. A
// handle outside the port's cone is moved onto it at the same distance; a handle at the port
// itself keeps the port's axis.
FulcrumPose fulcrum_pose(const TrocarPort& port, double length_m, const Eigen::Vector3d& handle_m);

// How the tip moves for a small motion of the handle, dtip = J · dhandle, with
// J = s sᵀ − (inside / outside)(I − s sᵀ) (s: the shaft): along the shaft one for one, across it
// reversed and scaled by the lever. Withdrawn: zero.
Eigen::Matrix3d fulcrum_jacobian(const FulcrumPose& pose);

// The force felt at the handle for a force on the tip, by virtual work through the frictionless
// port: Jᵀ · tip force (J is symmetric): along the shaft as it is, across it reversed and scaled by
// inside / outside.
Eigen::Vector3d handle_force_n(const FulcrumPose& pose, const Eigen::Vector3d& tip_force_n);

}  // namespace liversim
