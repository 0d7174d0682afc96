// Tools on the liver (issue 7): their shapes, contact that keeps them out of the tissue with the
// tissue's reaction as the force on the tool, and the forceps' grasp. A soft block fixed at its
// base stands in for the liver.
#include "block_mesh.h"

#include "liversim/engine/forces.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/model.h"
#include "liversim/engine/model_building.h"
#include "liversim/interaction/tools.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <span>

namespace liversim {
namespace {

constexpr double kBlockTop = 0.04;  // m: the block spans [0, 0.06] × [0, 0.05] × [0, 0.04]

struct Block {
  TetMesh mesh = testing::block_mesh(6, 5, 4, {0.06, 0.05, kBlockTop}, 0.2);
  SimModel model;
  BoundarySurface surface;
  Block() {
    ModelOptions options;
    options.mass_damping_per_s = 30.0;  // settles in about a second
    for (std::size_t n = 0; n < mesh.node_count(); ++n)
      if (mesh.rest_position_m.z[n] < 1e-9)
        options.fixed_nodes.push_back(static_cast<NodeIndex>(n));
    model = build_model(mesh, options);
    surface = extract_surface(mesh);
  }
};

// Tool pointing down at the top face's centre, its working end `height_m` above the face.
Tool tool_above_centre(ToolKind kind, double height_m) {
  Tool tool;
  tool.kind = kind;
  tool.pose.origin_m = Eigen::Vector3d(0.03, 0.025, kBlockTop + height_m);
  return tool;
}

// At `position` with the tool's springs: what the fixed base carries (Σ_fixed f_int) and the
// residual R = Σ_free |f_int + f_springs|, zero at equilibrium.
struct Balance {
  Eigen::Vector3d support_n = Eigen::Vector3d::Zero();
  double residual_n = 0.0;
};
Balance balance_of(const SimModel& model, const NodeArray& position,
                   std::span<const NodeSpring> springs) {
  NodeArray internal;
  internal.resize(model.node_count);
  ForceScratch scratch = make_force_scratch(model);
  compute_elastic_forces(model, position, scratch, internal);
  Balance balance;
  for (std::size_t n = 0; n < model.node_count; ++n)
    if (model.is_fixed[n]) balance.support_n += internal.at(n);
  add_external_forces({{}, springs}, position, internal);
  for (std::size_t n = 0; n < model.node_count; ++n)
    if (!model.is_fixed[n]) balance.residual_n += internal.at(n).norm();
  return balance;
}

TEST(Tools, PartsFollowThePoseAndTheJaws) {
  Tool forceps;
  forceps.kind = ToolKind::forceps;
  forceps.pose.origin_m = Eigen::Vector3d(0.1, 0.2, 0.3);
  // Shaft along +y in the scene: a quarter turn about x takes the tool's +z there.
  forceps.pose.orientation =
      Eigen::Quaterniond(Eigen::AngleAxisd(-std::numbers::pi / 2, Eigen::Vector3d::UnitX()));
  std::array<Capsule, 3> parts;
  forceps.jaw_opening = 0.0;
  ASSERT_EQ(tool_capsules(forceps, parts), 3);
  const ToolGeometry& g = forceps.geometry;
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  // Round-off of one rotation of vectors of ~0.3 m.
  constexpr double kRoundOff = 1e-15;
  EXPECT_NEAR((parts[0].b_m - (forceps.pose.origin_m + g.shaft_length_m * y)).norm(), 0.0,
              kRoundOff);
  // Closed: both jaws end on the axis, a jaw length ahead of the hinge; the grasp point is
  // halfway along them.
  const Eigen::Vector3d ahead = forceps.pose.origin_m - g.jaw_length_m * y;
  EXPECT_NEAR((parts[1].b_m - ahead).norm(), 0.0, kRoundOff);
  EXPECT_NEAR((parts[2].b_m - ahead).norm(), 0.0, kRoundOff);
  EXPECT_NEAR(
      (forceps_grasp_point_m(forceps) - (forceps.pose.origin_m - 0.5 * g.jaw_length_m * y)).norm(),
      0.0, kRoundOff);
  // Open: the jaw tips are 2·L·sin θ apart.
  forceps.jaw_opening = 1.0;
  tool_capsules(forceps, parts);
  EXPECT_NEAR((parts[1].b_m - parts[2].b_m).norm(),
              2.0 * g.jaw_length_m * std::sin(g.max_jaw_angle_rad), kRoundOff);

  Tool probe;
  EXPECT_EQ(tool_capsules(probe, parts), 2);
  EXPECT_EQ(parts[0].radius_m, probe.geometry.probe_tip_radius_m);
  EXPECT_EQ(tool_name(ToolKind::scalpel), "scalpel");
}

// The closest points of a segment and a triangle in each configuration: above the interior,
// beside an edge, through the face.
TEST(Tools, SegmentTriangleClosestPoints) {
  const Eigen::Vector3d p0(0, 0, 0), p1(1, 0, 0), p2(0, 1, 0);
  auto closest = [&](Eigen::Vector3d a, Eigen::Vector3d b) {
    return segment_triangle_closest(a, b, p0, p1, p2);
  };
  SegmentTriangleClosest c = closest({0.2, 0.3, 0.5}, {0.2, 0.3, 2.0});
  EXPECT_NEAR(c.distance, 0.5, 1e-15);
  EXPECT_NEAR((c.on_triangle - Eigen::Vector3d(0.2, 0.3, 0.0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(c.weight[0], 0.5, 1e-15);
  EXPECT_NEAR(c.weight[1], 0.2, 1e-15);
  EXPECT_NEAR(c.weight[2], 0.3, 1e-15);
  // Beside the hypotenuse, across it, 0.1 above the face's plane: the end nearest the face is
  // closest to the hypotenuse's midpoint.
  c = closest({0.75, 0.75, 0.1}, {1.5, 1.5, 0.1});
  EXPECT_NEAR((c.on_triangle - Eigen::Vector3d(0.5, 0.5, 0.0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(c.distance, std::sqrt(2 * 0.25 * 0.25 + 0.01), 1e-15);
  EXPECT_NEAR(c.weight[0], 0.0, 1e-15);
  EXPECT_NEAR(c.weight[1], 0.5, 1e-15);
  // Through the face.
  c = closest({0.25, 0.25, -1.0}, {0.25, 0.25, 1.0});
  EXPECT_EQ(c.distance, 0.0);
  EXPECT_NEAR((c.on_triangle - Eigen::Vector3d(0.25, 0.25, 0.0)).norm(), 0.0, 1e-15);
}

TEST(Tools, ProbeAwayFromTheTissueTouchesNothing) {
  const Block block;
  ToolInteraction hand(block.model, block.surface);
  const auto springs =
      hand.update(tool_above_centre(ToolKind::probe, 0.01), block.model.rest_position_m);
  EXPECT_TRUE(springs.empty());
  EXPECT_EQ(hand.force_on_tool_n(block.model.rest_position_m).norm(), 0.0);
}

// Pressed 4 mm into the top face, between nodes (1 cm apart, the ball is 3 mm), and held: the
// tissue gets out of the way, and at equilibrium the force on the probe is what the block's base
// carries: F_tool = −Σ_fixed f_int, up to the residual R.
TEST(Tools, ProbeContactPushesTheTissueAndFeelsTheSupportReaction) {
  const Block block;
  const SimModel& model = block.model;
  ToolInteraction hand(model, block.surface);
  SimState state = make_rest_state(model);
  const double radius = Tool{}.geometry.probe_tip_radius_m, press = 0.004;
  const Tool probe = tool_above_centre(ToolKind::probe, radius - press);
  for (int interval = 0; interval < 2000; ++interval)
    advance(model, state, {{}, hand.update(probe, state.position_m)}, 1e-3);
  const auto springs = hand.update(probe, state.position_m);
  ASSERT_GT(hand.contact_count(), 0u);

  // How deep the ball still is in the tissue: below the faces under it.
  const SurfaceBvh& bvh = hand.bvh();
  double deepest = 0.0;
  for (const auto& t : bvh.triangles()) {
    const SegmentTriangleClosest c = segment_triangle_closest(
        probe.pose.origin_m, probe.pose.origin_m, state.position_m.at(t[0]),
        state.position_m.at(t[1]), state.position_m.at(t[2]));
    deepest = std::max(deepest, radius - c.distance);
  }
  EXPECT_GT(deepest, 0.0);  // penalty contact: some overlap carries the force
  EXPECT_LT(deepest, 0.3 * press) << "the contact let the probe sink into the tissue";

  const Balance balance = balance_of(model, state.position_m, springs);
  const Eigen::Vector3d on_tool = hand.force_on_tool_n(state.position_m);
  EXPECT_GT(on_tool.z(), 0.0);  // the tissue pushes the probe back up
  EXPECT_LE(balance.residual_n, 1e-2 * on_tool.norm()) << "not settled";
  // Σ_all f_int = 0 exactly, so −Σ_fixed f_int = Σ_free f_int = −Σ f_springs + (net, |·| ≤ R).
  EXPECT_LE((on_tool + balance.support_n).norm(), balance.residual_n + 1e-12 * on_tool.norm());
}

// A part whose axis lies behind a face's plane but passes beside the face (its closest point on
// the face's edge) has not gone through it: the face is pushed aside by what the part overlaps it
// (radius − distance), not along its normal by the axis's depth, which jumped from nothing to
// millimetres as the axis passed the edge and flung the light nodes of a cut (issue 42).
TEST(Tools, AFaceAPartPassesBesideIsPushedAsideNotThroughItsDepth) {
  const Block block;
  const SimModel& model = block.model;
  ContactScratch scratch;
  std::vector<NodeSpring> springs;
  // A blade upright, its axis 0.2 mm outside the block's side face x = 0.06 and reaching 8 mm
  // below the top: behind the top faces' plane, beside them.
  const double radius = 0.0005, outside = 0.0002;
  const Capsule beside{{0.06 + outside, 0.025, kBlockTop + 0.01},
                       {0.06 + outside, 0.025, kBlockTop - 0.008},
                       radius};
  std::vector<PartContact> met(1);
  add_contact_springs(model, SurfaceBvh(block.surface, model.rest_position_m),
                      model.rest_position_m, std::span(&beside, 1), ContactSettings{}, scratch,
                      springs, met);
  ASSERT_FALSE(springs.empty());
  // Away from the upright axis, horizontally; a node's spring sums its faces' shares (force
  // Σ w·k·push over stiffness Σ w²·k), so its anchor may lie a few pushes away, never the 8.5 mm
  // of the axis's depth.
  for (const NodeSpring& spring : springs) {
    const Eigen::Vector3d push = spring.anchor_m - model.rest_position_m.at(spring.node);
    EXPECT_LT(push.x(), 0.0) << "node " << spring.node << " not pushed away from the blade";
    EXPECT_NEAR(push.z(), 0.0, 1e-12) << "node " << spring.node << " pushed along the top's normal";
    EXPECT_LE(push.norm(), 6.0 * (radius - outside)) << "node " << spring.node;
  }
  // What the blade met: the reaction of the springs at those positions, and where along it.
  Eigen::Vector3d reaction = Eigen::Vector3d::Zero();
  for (const NodeSpring& spring : springs)
    reaction -=
        spring.stiffness_n_per_m * (spring.anchor_m - model.rest_position_m.at(spring.node));
  ASSERT_TRUE(met[0].touched());
  EXPECT_LT((met[0].force_on_part_n - reaction).norm(), 1e-9 * reaction.norm());
  EXPECT_GT(met[0].force_on_part_n.x(), 0.0);           // the side face pushes the blade away
  const double top_at = 0.01 / 0.018, bottom_at = 1.0;  // the block's side from top to tip
  EXPECT_GE(met[0].touched_from, top_at - 1e-9);
  EXPECT_LE(met[0].touched_to, bottom_at + 1e-9);
  EXPECT_FALSE(met[0].pierced) << "beside the block, the blade is not through its surface";

  // Moved 1 mm inside the side, the blade's axis passes through the top: it is through.
  const Capsule through{
      {0.059, 0.025, kBlockTop + 0.01}, {0.059, 0.025, kBlockTop - 0.008}, radius};
  springs.clear();
  add_contact_springs(model, SurfaceBvh(block.surface, model.rest_position_m),
                      model.rest_position_m, std::span(&through, 1), ContactSettings{}, scratch,
                      springs, met);
  EXPECT_TRUE(met[0].pierced);
}

TEST(Tools, ForcepsGraspOnClosingPullAndReleaseOnOpening) {
  const Block block;
  const SimModel& model = block.model;
  ToolInteraction hand(model, block.surface);
  SimState state = make_rest_state(model);
  // Jaws open, their grasp point on the top face.
  Tool forceps = tool_above_centre(ToolKind::forceps, 0.0);
  forceps.jaw_opening = 1.0;
  forceps.pose.origin_m.z() +=
      0.5 * forceps.geometry.jaw_length_m * std::cos(forceps.geometry.max_jaw_angle_rad);
  const Eigen::Vector3d top_centre(0.03, 0.025, kBlockTop);
  hand.update(forceps, state.position_m);
  EXPECT_FALSE(hand.grasping());
  // Closing on air (lifted 3 cm) takes nothing.
  Tool lifted = forceps;
  lifted.jaw_opening = 0.0;
  lifted.pose.origin_m.z() += 0.03;
  hand.update(lifted, state.position_m);
  EXPECT_FALSE(hand.grasping());
  lifted.jaw_opening = 1.0;
  hand.update(lifted, state.position_m);

  forceps.jaw_opening = 0.0;
  hand.update(forceps, state.position_m);
  ASSERT_TRUE(hand.grasping());
  for (NodeIndex n : hand.grasp()->nodes)
    EXPECT_LT((model.rest_position_m.at(n) - top_centre).norm(), GraspSettings{}.radius_m);
  // Half-open is still held (hysteresis).
  forceps.jaw_opening = 0.4;
  hand.update(forceps, state.position_m);
  EXPECT_TRUE(hand.grasping());
  forceps.jaw_opening = 0.0;

  // Lift by 5 mm: the held tissue follows and pulls the forceps back down.
  forceps.pose.origin_m.z() += 0.005;
  for (int interval = 0; interval < 1000; ++interval)
    advance(model, state, {{}, hand.update(forceps, state.position_m)}, 1e-3);
  double lifted_mm = 0.0;
  for (NodeIndex n : hand.grasp()->nodes)
    lifted_mm =
        std::max(lifted_mm, 1e3 * (state.position_m.at(n) - model.rest_position_m.at(n)).z());
  EXPECT_GT(lifted_mm, 2.5);
  // The force on the forceps is the tissue's reaction: down, and what the base carries.
  const auto springs = hand.update(forceps, state.position_m);
  const Balance balance = balance_of(model, state.position_m, springs);
  const Eigen::Vector3d on_tool = hand.force_on_tool_n(state.position_m);
  EXPECT_LT(on_tool.z(), -0.5 * on_tool.norm());
  EXPECT_LE(balance.residual_n, 1e-2 * on_tool.norm()) << "not settled";
  EXPECT_LE((on_tool + balance.support_n).norm(), balance.residual_n + 1e-12 * on_tool.norm());

  forceps.jaw_opening = 1.0;
  hand.update(forceps, state.position_m);
  EXPECT_FALSE(hand.grasping());
}

// Two hands over the same surface: the second may query the first's hierarchy, refitted to the
// tissue as it is now, instead of refitting its own, and meets exactly what its own would give.
TEST(Tools, AHandQueryingTheOtherHandsRefittedHierarchyMeetsWhatItsOwnGives) {
  const Block block;
  const SimModel& model = block.model;
  SimState state = make_rest_state(model);
  ToolInteraction pressing(model, block.surface);
  const double radius = Tool{}.geometry.probe_tip_radius_m;
  const Tool probe = tool_above_centre(ToolKind::probe, radius - 0.004);
  for (int interval = 0; interval < 200; ++interval)
    advance(model, state, {{}, pressing.update(probe, state.position_m)}, 1e-3);
  // The whole block and the tools 5 cm along x: a hierarchy not refitted to it would meet nothing.
  const Eigen::Vector3d shift(0.05, 0.0, 0.0);
  for (std::size_t n = 0; n < model.node_count; ++n)
    state.position_m.set(n, state.position_m.at(n) + shift);
  Tool probe_moved = probe;
  probe_moved.pose.origin_m += shift;
  pressing.update(probe_moved, state.position_m);  // its hierarchy now fits the moved tissue
  ASSERT_GT(pressing.contact_count(), 0u);

  Tool forceps = tool_above_centre(ToolKind::forceps, 0.0);
  forceps.pose.origin_m += shift;
  forceps.pose.origin_m.x() += 0.01;  // beside the probe, jaws closed on the top face
  forceps.jaw_opening = 0.0;
  auto same_springs = [](std::span<const NodeSpring> a, std::span<const NodeSpring> b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a[i].node != b[i].node || a[i].anchor_m != b[i].anchor_m ||
          a[i].stiffness_n_per_m != b[i].stiffness_n_per_m ||
          a[i].damping_n_s_per_m != b[i].damping_n_s_per_m)
        return false;
    return true;
  };
  for (const Tool& tool : {forceps, probe_moved}) {
    ToolInteraction own(model, block.surface), sharing(model, block.surface);
    const auto own_springs = own.update(tool, state.position_m);
    const std::vector<NodeSpring> by_own(own_springs.begin(), own_springs.end());
    const auto by_sharing = sharing.update(tool, state.position_m, false, &pressing.bvh());
    EXPECT_FALSE(by_own.empty());
    EXPECT_TRUE(same_springs(by_own, by_sharing));
    EXPECT_EQ(own.grasping(), sharing.grasping());
    EXPECT_EQ(own.contact_count(), sharing.contact_count());
  }
}

TEST(Tools, BadSettingsAreNamed) {
  const Block block;
  ContactSettings contact;
  contact.frequency_hz = std::nan("");
  EXPECT_THROW(ToolInteraction(block.model, block.surface, contact), std::invalid_argument);
  GraspSettings grasp;
  grasp.release_above = 0.1;  // below close_below
  EXPECT_THROW(ToolInteraction(block.model, block.surface, {}, grasp), std::invalid_argument);
}

}  // namespace
}  // namespace liversim
