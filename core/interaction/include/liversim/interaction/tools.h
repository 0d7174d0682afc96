#pragma once
// Surgical tools as rigid shapes with a pose, and what they do to the liver: contact that keeps
// them out of the tissue, and the forceps' grasp. Both act through damped node springs (forces.h),
// recomputed at every interval from the deformed surface, so the force on the tool is the
// reaction of the tissue on those springs, in newtons.

#include "liversim/engine/forces.h"
#include "liversim/engine/surface_bvh.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace liversim {

enum class ToolKind { probe, forceps, scalpel };
inline constexpr std::array<ToolKind, 3> kToolKinds = {ToolKind::probe, ToolKind::forceps,
                                                       ToolKind::scalpel};
std::string_view tool_name(ToolKind kind);
// The tool named `name` (as tool_name names it), if any.
std::optional<ToolKind> tool_kind(std::string_view name);

// The surgeon's hands: each may hold a tool, and both act in the same step (one holds and
// retracts while the other cuts). The device (or the mouse) moves the right hand's tool.
enum class Hand : std::uint8_t { right, left };
inline constexpr std::array<Hand, 2> kHands = {Hand::right, Hand::left};
constexpr std::size_t hand_index(Hand hand) {
  return static_cast<std::size_t>(hand);
}
std::string_view hand_name(Hand hand);  // "right", "left"
std::optional<Hand> hand_named(std::string_view name);

// A segment swept by a sphere: every tool part is one.
struct Capsule {
  Eigen::Vector3d a_m, b_m;
  double radius_m = 0.0;
};

// Sizes of 5 mm laparoscopic instruments. In the tool's frame the working end (probe ball, jaw
// hinge, blade heel) is at the origin, the shaft runs along +z toward the hand, the jaws and the
// blade reach along −z, and the jaws open in the x–z plane.
struct ToolGeometry {
  double shaft_radius_m = 0.0025;
  double shaft_length_m = 0.06;  // the part that can reach the tissue
  double probe_tip_radius_m = 0.003;
  double jaw_length_m = 0.02;
  double jaw_radius_m = 0.0015;
  double max_jaw_angle_rad = 0.35;  // each jaw off the axis when fully open (20°)
  double blade_length_m = 0.02;
  double blade_half_thickness_m = 0.0005;
  bool operator==(const ToolGeometry&) const = default;
};

struct ToolPose {
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();

  Eigen::Vector3d to_scene(const Eigen::Vector3d& local_m) const {
    return origin_m + orientation * local_m;
  }
};

struct Tool {
  ToolKind kind = ToolKind::probe;
  ToolPose pose;
  double jaw_opening = 1.0;  // forceps: 0 closed, 1 fully open
  // Scalpel: the blade may break in and cut (a device's cut button held); disarmed it only pushes,
  // and a blade already in passes on without cutting until armed again or drawn out.
  bool blade_armed = true;
  ToolGeometry geometry;
};

// The tool's parts in the scene: shaft and ball (probe), shaft and two jaws (forceps), shaft and
// blade (scalpel). Returns how many of `parts` it wrote.
int tool_capsules(const Tool& tool, std::array<Capsule, 3>& parts);
inline constexpr int kScalpelBlade = 1;  // the scalpel's blade among its parts (heel to tip)
// Forceps: the point midway between the jaws, where a closing grasp takes hold.
Eigen::Vector3d forceps_grasp_point_m(const Tool& tool);

// Closest point of segment [a, b] to p.
Eigen::Vector3d closest_point_on_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                         const Eigen::Vector3d& p);

// Closest point of triangle (p0, p1, p2) to p, with its barycentric weights.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& p0,
                                          const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                                          std::array<double, 3>& weight);

// Closest points of segment [a, b] and triangle (p0, p1, p2): the point on the triangle with its
// barycentric weights. Distance 0 when the segment passes through the triangle.
struct SegmentTriangleClosest {
  Eigen::Vector3d on_segment, on_triangle;
  std::array<double, 3> weight;
  double distance;
};
SegmentTriangleClosest segment_triangle_closest(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                const Eigen::Vector3d& p0,
                                                const Eigen::Vector3d& p1,
                                                const Eigen::Vector3d& p2);

// Penalty contact against the surface triangles: where a part reaches within its radius of a
// triangle, the triangle's closest point is pushed out of the part (radially from the part's axis,
// or, once the axis has gone through the face or lies behind its interior, along the face's
// inward normal by the radius and the axis's depth behind it) by a critically
// damped spring whose stiffness gives the mass at that point the contact frequency; the corners
// share it by their barycentric weights (force w·k·push, stiffness w²·k), and each node gets one
// spring with the sum of its shares. A thin tool between nodes still meets the faces.
struct ContactSettings {
  // High enough that the tissue gives way well before the tool sinks in (a few tenths of a mm at
  // a probe's push), low enough that the 1 ms step stays below the explicit stability limit.
  double frequency_hz = 150.0;
};

// Per-node sums of one contact evaluation; zero between evaluations.
struct ContactScratch {
  std::vector<double> stiffness_n_per_m;
  std::vector<Eigen::Vector3d> force_n;
  std::vector<NodeIndex> touched;
  void resize(std::size_t nodes) {
    if (stiffness_n_per_m.size() == nodes) return;
    stiffness_n_per_m.assign(nodes, 0.0);
    force_n.assign(nodes, Eigen::Vector3d::Zero());
    touched.clear();
    touched.reserve(nodes);
  }
  // Adds a share to the node's sums: its force at the positions evaluated and its stiffness.
  void add(NodeIndex node, const Eigen::Vector3d& share_force_n, double share_stiffness_n_per_m) {
    const auto n = static_cast<std::size_t>(node);
    if (stiffness_n_per_m[n] == 0.0) touched.push_back(node);
    stiffness_n_per_m[n] += share_stiffness_n_per_m;
    force_n[n] += share_force_n;
  }
  // Appends one spring per touched node, giving its summed force at `position` with its summed
  // stiffness, damped at `damping_ratio` of critical; zeroes the sums. Returns how many.
  std::size_t add_springs(const SimModel& model, const NodeArray& position,
                          std::vector<NodeSpring>& springs, double damping_ratio = 1.0);
};

// What one tool part met in a contact evaluation: the tissue's force on it (the springs' elastic
// part at the positions evaluated, N) and the stretch of its axis that touched the tissue, as
// parameters along it (0 at a, 1 at b).
struct PartContact {
  Eigen::Vector3d force_on_part_n = Eigen::Vector3d::Zero();
  double touched_from = 1.0, touched_to = 0.0;  // from > to: it touched nothing
  bool pierced = false;           // its axis passes through a face: it is through the surface
  bool touched_cut_face = false;  // a face it touched was made by a cut: it is in a cut
  // The region (SimModel::regions) of the element whose face pushed it hardest, and that push
  // (N); -1 when the surface does not say which element a face bounds.
  std::int32_t region = -1;
  double hardest_push_n = 0.0;
  bool touched() const { return touched_from <= touched_to; }
};

// Finds the faces in contact through the hierarchy (refitted to `position` by the caller) and
// appends one spring per pushed free node to `springs`; returns how many. `per_part` (empty, or
// one per part) receives what each part met. Allocates nothing when the scratch is sized and
// `springs` has the capacity.
std::size_t add_contact_springs(const SimModel& model, const SurfaceBvh& bvh,
                                const NodeArray& position, std::span<const Capsule> parts,
                                const ContactSettings& settings, ContactScratch& scratch,
                                std::vector<NodeSpring>& springs,
                                std::span<PartContact> per_part = {},
                                std::span<const std::uint8_t> cut_triangle = {});

// The forceps' hold on the tissue: the surface nodes near the jaws when they closed,
// carried rigidly with the tool from then on. Empty: no hold.
struct ForcepsGrasp {
  std::vector<NodeIndex> nodes;
  std::vector<Eigen::Vector3d> offset_in_tool_m;  // node position at the grasp, in the tool frame
  std::vector<double> stiffness_n_per_m;
  std::vector<double> damping_n_s_per_m;

  bool empty() const { return nodes.empty(); }
  void clear() {
    nodes.clear();
    offset_in_tool_m.clear();
    stiffness_n_per_m.clear();
    damping_n_s_per_m.clear();
  }
};

struct GraspSettings {
  double close_below = 0.3;    // jaw opening at which the jaws take hold
  double release_above = 0.5;  // and let go (hysteresis: a hold does not flicker)
  double radius_m = 0.01;      // surface nodes this close to the closed jaws are held
  double total_stiffness_n_per_m = 300.0;
};

// A tool acting on the liver, one interval at a time: contact of all its parts, and for the forceps
// the grasp, taken when the jaws close on tissue and let go when they open.
class ToolInteraction {
 public:
  ToolInteraction(const SimModel& model, const BoundarySurface& surface,
                  ContactSettings contact = {}, GraspSettings grasp = {});

  // The springs for the next interval at the tool's pose and the tissue's `position`. A scalpel
  // whose blade is cutting (`blade_cuts`) does not push: it passes into the tissue it separates,
  // its shaft too when deeper than the blade (cutting_edge_m). Allocates nothing (every buffer is
  // sized for the whole surface at construction). Given `refitted`, the hierarchy of another
  // interaction over the same surface already refitted to `position` (the other hand's, this
  // step), it is queried instead of refitting this one's: the same boxes, half the refits.
  std::span<const NodeSpring> update(const Tool& tool, const NodeArray& position,
                                     bool blade_cuts = false, const SurfaceBvh* refitted = nullptr);
  // The springs of the last update.
  std::span<const NodeSpring> springs() const { return springs_; }

  // The force of the tissue on the tool at `position` with the springs of the last update (N).
  Eigen::Vector3d force_on_tool_n(const NodeArray& position) const {
    return spring_reaction_force_n(springs_, position);
  }
  bool grasping() const { return !grasp_.empty(); }
  // The tool has left the scene: let go of any hold, no springs.
  void release() {
    grasp_.clear();
    springs_.clear();
    part_contact_ = {};
    contact_count_ = 0;
  }
  const ForcepsGrasp* grasp() const { return grasping() ? &grasp_ : nullptr; }
  // Takes over the hold `held` of the model this one was cut from: each node of this model that
  // came from a held node (`node_origin`, CutResult's) is held as it was, its share of the
  // stiffness split among the copies a cut made of it. Held nodes that are gone (taken out with a
  // free body) are let go. So forceps in one hand keep their hold while the other hand cuts.
  void carry_hold(const ForcepsGrasp& held, std::span<const NodeIndex> node_origin);
  std::size_t contact_count() const { return contact_count_; }
  // What part `i` of the tool (tool_capsules' order) met in the last update; a part that did not
  // push (the jaws of a hold, a cutting blade) met nothing.
  const PartContact& part_contact(int i) const {
    return part_contact_[static_cast<std::size_t>(i)];
  }
  const SurfaceBvh& bvh() const { return bvh_; }

 private:
  void try_grasp(const Tool& tool, const NodeArray& position, const SurfaceBvh& hierarchy);

  const SimModel* model_;
  SurfaceBvh bvh_;
  ContactSettings contact_;
  GraspSettings grasp_settings_;
  // Sized for every surface node once, so that closing the jaws in a step allocates nothing.
  ForcepsGrasp grasp_;
  std::vector<double> grasp_weight_;
  std::vector<std::uint8_t> node_mark_;
  std::vector<std::uint8_t> cut_triangle_;  // per surface triangle: made by a cut
  ContactScratch contact_scratch_;
  std::vector<NodeSpring> springs_;
  std::array<PartContact, 3> part_contact_;
  std::size_t contact_count_ = 0;
};

}  // namespace liversim
