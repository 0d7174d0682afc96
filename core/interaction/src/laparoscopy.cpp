#include "liversim/interaction/laparoscopy.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace liversim {

std::optional<std::string> validate(const TrocarPort& port, double instrument_length_m) {
  std::ostringstream problem;
  if (!port.position_m.allFinite())
    problem << "the port's position is not finite";
  else if (!port.axis.allFinite() || std::abs(port.axis.norm() - 1.0) > 1e-9)
    problem << "the port's axis is not a unit vector (its length is " << port.axis.norm() << ")";
  else if (!(port.cone_half_angle_rad > 0.0 && port.cone_half_angle_rad < 0.5 * std::numbers::pi))
    problem << "the port's cone half-angle " << port.cone_half_angle_rad
            << " rad is not between 0 and π/2";
  else if (!(std::isfinite(instrument_length_m) && instrument_length_m > 0.0))
    problem << "the instrument's length " << instrument_length_m << " m is not positive";
  else
    return std::nullopt;
  return problem.str();
}

Eigen::Quaterniond FulcrumPose::orientation() const {
  return Eigen::Quaterniond::FromTwoVectors(-Eigen::Vector3d::UnitZ(), shaft);
}

FulcrumPose fulcrum_pose(const TrocarPort& port, double length_m, const Eigen::Vector3d& handle_m) {
  FulcrumPose pose;
  const Eigen::Vector3d to_port = port.position_m - handle_m;
  pose.outside_m = to_port.norm();
  pose.shaft = pose.outside_m > 0.0 ? Eigen::Vector3d(to_port / pose.outside_m) : port.axis;
  // The cone: the shaft within its half-angle of the axis, turned toward the axis in their plane
  // when it is not.
  const double cos_angle = std::clamp(pose.shaft.dot(port.axis), -1.0, 1.0);
  const double angle = std::acos(cos_angle);
  if (angle > port.cone_half_angle_rad) {
    pose.at_cone_limit = true;
    Eigen::Vector3d across = pose.shaft - cos_angle * port.axis;
    if (across.norm() < 1e-12) {  // straight out of the body: any direction on the cone
      across = port.axis.unitOrthogonal();
    }
    across.normalize();
    pose.shaft = std::cos(port.cone_half_angle_rad) * port.axis +
                 std::sin(port.cone_half_angle_rad) * across;
  }
  pose.handle_m = port.position_m - pose.outside_m * pose.shaft;
  pose.inside_m = length_m - pose.outside_m;
  if (pose.inside_m <= 0.0) {
    pose.inside_m = 0.0;
    pose.withdrawn = true;
  }
  pose.tip_m = port.position_m + pose.inside_m * pose.shaft;
  return pose;
}

Eigen::Matrix3d fulcrum_jacobian(const FulcrumPose& pose) {
  if (pose.withdrawn || !(pose.outside_m > 0.0)) return Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d along = pose.shaft * pose.shaft.transpose();
  return along - (pose.inside_m / pose.outside_m) * (Eigen::Matrix3d::Identity() - along);
}

Eigen::Vector3d handle_force_n(const FulcrumPose& pose, const Eigen::Vector3d& tip_force_n) {
  return fulcrum_jacobian(pose).transpose() * tip_force_n;
}

}  // namespace liversim
