#pragma once
// Contact between the bodies of a cut model: the organ and the pieces cut free (cutting.h). A
// node of one body that has gone behind a face of another, by at most kBodyContactReachM, is
// pushed back out along the face's outward normal by a penalty spring, and the face's three
// corners are pushed the other way by the same force, shared by the node's barycentric weights
// on the face (node-to-surface penalty contact, as SOFA's and most surgical simulators' is). The
// springs are made before every step from the positions then (as the tools' are), so that the
// integrators, the step's limit and the energy books take them like any tool's spring: a freed
// specimen rests on the organ instead of falling through it.
//
// The penalty's frequency is the support's (SimModel::support_frequency_fraction of the mesh's
// highest): k = ω_c²·m with m the lightest surface node's mass, the same for every contact, so
// that the push is the gradient of ½·k·d² and no spring of one contact is faster than ω_c. A
// corner of weight w takes w·k·d and stiffness w²·k (as a tool's contact shares its push); a node
// in several contacts takes one spring with their sums (ContactScratch), damped as the support
// is. Frictionless.

#include "liversim/engine/forces.h"
#include "liversim/engine/model.h"
#include "liversim/engine/surface.h"
#include "liversim/engine/surface_bvh.h"
#include "liversim/interaction/cutting.h"
#include "liversim/interaction/tools.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace liversim {

// How far behind another body's face a node is still pushed out of it. Deeper, it is taken to
// have passed through (the face is of the far side of a thin part) and is left alone.
inline constexpr double kBodyContactReachM = 0.002;

class BodyContact {
 public:
  BodyContact() = default;
  // For a model whose free bodies are `bodies` (free_bodies) and whose boundary is `surface`
  // (boundary_surface). Inactive, with no hierarchy, when there is no free body.
  BodyContact(const SimModel& model, const BoundarySurface& surface,
              std::span<const FreeBody> bodies);

  bool active() const { return !hierarchy_.empty(); }
  // The most springs add_springs appends (for a caller that reserves so as not to allocate).
  std::size_t max_springs() const { return surface_nodes_.size(); }

  // Appends the springs of every contact at `position` to `springs`. `refitted`: a hierarchy of
  // the same surface already refitted to `position` (a tool's, this step), queried instead of
  // refitting this one's. Allocates nothing once `springs` has room for max_springs() more.
  void add_springs(const SimModel& model, const NodeArray& position,
                   std::vector<NodeSpring>& springs, const SurfaceBvh* refitted = nullptr);
  // Contacts (node behind a face) the last add_springs found.
  std::size_t contacts() const { return contacts_; }

 private:
  SurfaceBvh hierarchy_;
  std::vector<std::int32_t> body_of_triangle_;  // 0: the organ, 1 + i: free body i
  std::vector<NodeIndex> surface_nodes_;
  std::vector<std::int32_t> body_of_surface_node_;
  std::vector<Aabb> body_box_;      // per body, for one add_springs
  double stiffness_n_per_m_ = 0.0;  // ω_c²·(the lightest surface node's mass)
  ContactScratch scratch_;          // per mesh node, for one add_springs
  std::size_t contacts_ = 0;
};

}  // namespace liversim
