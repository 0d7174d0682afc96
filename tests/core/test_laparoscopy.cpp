// The laparoscopic fulcrum (issue 43, item 4; docs/laparoscopy.md) against hand-computed cases: a
// 30 cm instrument through a port at the origin whose axis points down (−z).
#include "liversim/interaction/laparoscopy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace liversim {
namespace {

constexpr double kLength_m = 0.3;

TrocarPort port_at_origin() {
  TrocarPort port;
  port.axis = -Eigen::Vector3d::UnitZ();
  port.cone_half_angle_rad = std::numbers::pi / 6.0;  // 30°
  return port;
}

// The handle 10 cm above the port: 20 cm of the shaft inside, straight down.
TEST(Fulcrum, TheTipIsTheInstrumentsLengthFromTheHandleThroughThePort) {
  const FulcrumPose pose = fulcrum_pose(port_at_origin(), kLength_m, {0.0, 0.0, 0.1});
  EXPECT_DOUBLE_EQ(pose.outside_m, 0.1);
  EXPECT_DOUBLE_EQ(pose.inside_m, 0.2);
  EXPECT_LT((pose.tip_m - Eigen::Vector3d(0.0, 0.0, -0.2)).norm(), 1e-15);
  EXPECT_FALSE(pose.at_cone_limit);
  EXPECT_FALSE(pose.withdrawn);
  // The tool's working end (its −z) points down the shaft.
  EXPECT_LT((pose.orientation() * -Eigen::Vector3d::UnitZ() - pose.shaft).norm(), 1e-15);

  // 1 cm across: the handle at (0.01, 0, 0.1) is √0.0101 m from the port, so the tip is
  // 0.3 − √0.0101 m beyond it along (−0.01, 0, −0.1)/√0.0101.
  const FulcrumPose moved = fulcrum_pose(port_at_origin(), kLength_m, {0.01, 0.0, 0.1});
  const double outside = std::sqrt(0.0101);
  const double inside = kLength_m - outside;
  const Eigen::Vector3d expected_tip =
      inside / outside * Eigen::Vector3d(-0.01, 0.0, -0.1);  // (−0.0198511, 0, −0.198511)
  EXPECT_LT((moved.tip_m - expected_tip).norm(), 1e-15);
  EXPECT_NEAR(moved.tip_m.x(), -0.0198511, 1e-7);
}

// A small motion across the shaft moves the tip the other way by inside / outside: 2 with 20 cm
// inside and 10 cm out, 0.5 with 10 cm inside and 20 cm out; along the shaft, one for one.
TEST(Fulcrum, TheTipMovesOppositeByTheLeverThatTheInsertionDepthSets) {
  const double step_m = 1e-6;
  for (const auto& [height_m, lever] : {std::pair{0.1, 2.0}, std::pair{0.2, 0.5}}) {
    SCOPED_TRACE(height_m);
    const Eigen::Vector3d handle(0.0, 0.0, height_m);
    const FulcrumPose pose = fulcrum_pose(port_at_origin(), kLength_m, handle);
    EXPECT_DOUBLE_EQ(pose.inside_m / pose.outside_m, lever);
    const Eigen::Vector3d across =
        fulcrum_pose(port_at_origin(), kLength_m, handle + Eigen::Vector3d(step_m, 0.0, 0.0))
            .tip_m -
        pose.tip_m;
    // Second order in the step: the tip swings on a circle.
    EXPECT_NEAR(across.x(), -lever * step_m, 1e-11);
    EXPECT_NEAR(across.z(), 0.0, 1e-10);
    const Eigen::Vector3d pushed =
        fulcrum_pose(port_at_origin(), kLength_m, handle - Eigen::Vector3d(0.0, 0.0, step_m))
            .tip_m -
        pose.tip_m;
    EXPECT_NEAR(pushed.z(), -step_m, 1e-15);
    EXPECT_NEAR(pushed.x(), 0.0, 1e-18);
    // The Jacobian says the same.
    const Eigen::Matrix3d jacobian = fulcrum_jacobian(pose);
    EXPECT_NEAR(jacobian(0, 0), -lever, 1e-15);
    EXPECT_NEAR(jacobian(1, 1), -lever, 1e-15);
    EXPECT_NEAR(jacobian(2, 2), 1.0, 1e-15);
  }
  // At an angle, the Jacobian matches finite differences in every direction.
  const Eigen::Vector3d handle(0.03, -0.02, 0.12);
  const FulcrumPose pose = fulcrum_pose(port_at_origin(), kLength_m, handle);
  const Eigen::Matrix3d jacobian = fulcrum_jacobian(pose);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d step = 1e-6 * Eigen::Vector3d::Unit(k);
    const Eigen::Vector3d central =
        (fulcrum_pose(port_at_origin(), kLength_m, handle + step).tip_m -
         fulcrum_pose(port_at_origin(), kLength_m, handle - step).tip_m) /
        2e-6;
    EXPECT_LT((central - jacobian.col(k)).norm(), 1e-8) << "direction " << k;
  }
}

// The tip pushed sideways by 1 N with 20 cm inside and 10 cm out: the hand feels 2 N the other
// way; pushed along the shaft, the same 1 N. The work done by the hand equals the work done on the
// tissue for any small motion (virtual work).
TEST(Fulcrum, TheForceAtTheTipIsFeltAtTheHandleThroughTheSameLever) {
  const FulcrumPose pose = fulcrum_pose(port_at_origin(), kLength_m, {0.0, 0.0, 0.1});
  EXPECT_LT((handle_force_n(pose, {1.0, 0.0, 0.0}) - Eigen::Vector3d(-2.0, 0.0, 0.0)).norm(),
            1e-15);
  EXPECT_LT((handle_force_n(pose, {0.0, 0.0, 1.0}) - Eigen::Vector3d(0.0, 0.0, 1.0)).norm(), 1e-15);
  const FulcrumPose deeper = fulcrum_pose(port_at_origin(), kLength_m, {0.0, 0.0, 0.2});
  EXPECT_LT((handle_force_n(deeper, {0.0, 1.0, 0.0}) - Eigen::Vector3d(0.0, -0.5, 0.0)).norm(),
            1e-15);
  const FulcrumPose tilted = fulcrum_pose(port_at_origin(), kLength_m, {0.03, -0.02, 0.12});
  const Eigen::Vector3d tip_force(0.3, -0.7, 0.4), handle_motion(1e-3, 2e-3, -0.5e-3);
  const Eigen::Vector3d tip_motion = fulcrum_jacobian(tilted) * handle_motion;
  EXPECT_NEAR(handle_force_n(tilted, tip_force).dot(handle_motion), tip_force.dot(tip_motion),
              1e-16);
}

// A handle beyond the port's 30° cone is moved onto it at the same distance; one an instrument's
// length away leaves the tip at the port.
TEST(Fulcrum, TheConeHoldsTheShaftAndAWithdrawnInstrumentEndsAtThePort) {
  // 45° off the axis, 10 cm out: held at 30°, still 10 cm out, in the same vertical plane.
  const double off = 0.1 / std::sqrt(2.0);
  const FulcrumPose held = fulcrum_pose(port_at_origin(), kLength_m, {off, 0.0, off});
  EXPECT_TRUE(held.at_cone_limit);
  EXPECT_NEAR(held.outside_m, 0.1, 1e-15);
  EXPECT_LT((held.handle_m - Eigen::Vector3d(0.1 * std::sin(std::numbers::pi / 6.0), 0.0,
                                             0.1 * std::cos(std::numbers::pi / 6.0)))
                .norm(),
            1e-15);
  EXPECT_LT((held.tip_m - Eigen::Vector3d(-0.2 * 0.5, 0.0, -0.2 * std::sqrt(3.0) / 2.0)).norm(),
            1e-15);
  // Within the cone: as asked.
  EXPECT_FALSE(fulcrum_pose(port_at_origin(), kLength_m, {0.02, 0.0, 0.1}).at_cone_limit);

  const FulcrumPose out = fulcrum_pose(port_at_origin(), kLength_m, {0.0, 0.0, 0.35});
  EXPECT_TRUE(out.withdrawn);
  EXPECT_EQ(out.inside_m, 0.0);
  EXPECT_EQ(out.tip_m, Eigen::Vector3d::Zero());
  EXPECT_EQ(fulcrum_jacobian(out), Eigen::Matrix3d::Zero());
  EXPECT_EQ(handle_force_n(out, {1.0, 2.0, 3.0}), Eigen::Vector3d::Zero());
}

TEST(Fulcrum, ABadPortOrLengthIsNamed) {
  TrocarPort port = port_at_origin();
  EXPECT_FALSE(validate(port, kLength_m));
  port.axis = {0.0, 0.0, -2.0};
  EXPECT_NE(validate(port, kLength_m)->find("not a unit vector"), std::string::npos);
  port = port_at_origin();
  port.cone_half_angle_rad = 2.0;
  EXPECT_NE(validate(port, kLength_m)->find("cone half-angle"), std::string::npos);
  EXPECT_NE(validate(port_at_origin(), -0.1)->find("length -0.1 m"), std::string::npos);
  port = port_at_origin();
  port.position_m.x() = std::nan("");
  EXPECT_NE(validate(port, kLength_m)->find("position"), std::string::npos);
}

}  // namespace
}  // namespace liversim
