#pragma once
// Cutting: the scalpel's edge separates the tissue it sweeps through (cut_tissue may be limited to
// elements stressed past a threshold). In the real-time loop a blade breaks in once pressed with
// the force that makes new surface (the tissue's toughness times its edge in contact); short of
// that the tissue only deforms (plastically past the yield limit), and the dent stays.
//
// The cut follows the swept surface cleanly by node snapping with duplication (Nienhuys & van der
// Stappen 2001): the nearer node of each edge the surface crosses is moved onto the surface when
// every element it belongs to keeps its shape (and a node of the organ's surface moves only along
// it); the faces the surface then runs along are separated, and each node on them gets one copy
// per side. A snap shares the mass of the elements around the node by their new volumes, so no mass
// is lost. Where no node can be moved (a node of the surface off it, a neighbour that would
// flatten), a node is made where the surface crosses the edge, away from both ends, and the
// elements holding the edge are bisected on it (Mor & Kanade 2000 subdivide the elements a blade
// passes through likewise): a linear element's parts have its deformation gradient, so they carry
// its region, fibres, stress and viscous history exactly, and no part may be thinner than the
// mesh's smallest element. Only where neither works does an element the surface passes through go
// whole to the side of its centroid. A node whose parted surroundings would not be one manifold fan
// keeps its faces joined (a small bridge the next stroke cuts), so the surface stays manifold.
// A piece that comes free stays as a body of its own (a specimen: it deforms, falls under gravity
// and can be grasped and lifted out) unless it is a crumb smaller than min_free_body_volume_m3,
// which is taken out; either way its volume counts as resected. take_out_body removes a free body.
//
// The model stays constant between cuts: a cut makes a new model and state from the old ones.

#include "liversim/engine/model.h"
#include "liversim/engine/state.h"
#include "liversim/engine/surface.h"
#include "liversim/interaction/tools.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace liversim {

struct CuttingSettings {
  // Von Mises equivalent of the Cauchy stress (Pa) of an element the edge sweeps through, above
  // which cut_tissue separates it; 0: the edge cuts whatever it sweeps through (as a broken-in
  // blade does in the real-time loop).
  double cutting_stress_pa = 1500.0;
  // A blade breaks in once the force on it reaches the fracture toughness of the tissue it
  // touches (RegionMaterial::fracture_toughness_j_per_m2, per region of the model) times the
  // length of its edge in contact (a tip: the blade's thickness), the work per unit advance of a
  // crack that long (Mahvash & Hayward 2001, haptic rendering of cutting).
  //
  // A cutting blade is held back by the toughness times its edge in the tissue, against its
  // motion across the edge, and by the friction on its sides (RegionMaterial::
  // blade_friction_n_per_m) times the same edge, against its motion in any direction (drawn along
  // its edge or out of its cut, it still rubs); below this speed each grows from zero with the
  // speed it acts against (a still blade is not pushed back, and the force does not flip with the
  // hand's tremor).
  double full_resistance_speed_m_per_s = 0.005;
  // A node is moved onto the cut when the cut crosses one of its edges within this fraction of
  // the edge's length from it, and when every element it belongs to keeps at least
  // `snap_min_shape_fraction` of its smallest height and of its volume, at rest and deformed.
  double snap_fraction = 0.5;
  double snap_min_shape_fraction = 0.25;
  // Where no node could be moved, a node is made on an edge the cut crosses at least this fraction
  // of its length from either end (nearer, the element is left whole: a child that thin would set
  // the explicit step).
  double split_min_fraction = 0.25;
  // Elements the sweep touches whose longest edge is longer than this are bisected on it, a level
  // an update (0: never), so that a short stroke opens a crack on a coarse mesh: a crack opens
  // only at a node whose elements the cut parts all round, and a 2 cm stroke over elements 14 mm
  // across has none (issue 42).
  double refine_edge_m = 0.0;
  // ... but only over a stroke's first stretch: while its edge's middle has travelled at most this
  // far from where the stroke began (infinity: all along), and while the cuts have added less than
  // half the mass they may (max_added_mass_fraction; the rest is for the thin parts a cut itself
  // leaves). Past two elements of the coarsest shipped mesh a stroke opens its crack without
  // refinement, and refining all along spent the whole budget: the shipped wedge resection's four
  // passes exhausted it in their third, and the loop's step halved (issue 42).
  double refine_over_stroke_m = 0.03;
  // No element a snap moves or a split or refinement makes may be thinner than this at rest,
  // unless the mesh already had one as thin: the explicit step goes with the smallest height. (Each
  // guarding only relative to its own element, a refined mesh's cuts brought the step to 0.02 ms.)
  double min_part_height_m = 0.002;
  // The most mass a cut may add (as a fraction of the tissue's) so that its small parts do not
  // lower the explicit step (scale_masses_to_frequency); past it the step falls instead.
  double max_added_mass_fraction = 0.005;
  // A piece that comes free stays as a body of its own when its rest volume is at least this (a
  // specimen); smaller pieces (crumbs) are taken out at once (infinity: every piece is taken out).
  double min_free_body_volume_m3 = 1e-6;
  // A stroke drawn beside a cut already made, within this distance of its surface and within 10°
  // of parallel to it, follows that cut (0: never): a blade drawn into an incision is guided by
  // its lips instead of cutting a second sheet beside it. Deepening a groove stroke after stroke
  // in tissue that moved between the strokes otherwise cut sheets up to ~3 mm apart in the
  // material, whose slivers kept a lobe joined to the organ (issue 42). It is also the closest a
  // stroke can slice parallel to an earlier cut.
  double groove_guide_m = 0.004;
  // An interior face whose three nodes lie on cut faces and that lies in the cut's surface (within
  // this angle of parallel to a cut face at each of its nodes) is a hole in the cut: it is parted
  // at the stroke's end (part_remnants; 0: holes stay joined). Where a resection's passes met end
  // to end, neither passed all the way through the elements at the seam, and a 56 cm³ lobe hung by
  // one such face (issue 42).
  double hole_angle_deg = 20.0;
};

// The share of CuttingSettings::max_added_mass_fraction past which a stroke no longer refines.
inline constexpr double kRefinementBudgetShare = 0.5;

// The problem with the settings, if any (a message naming the setting, its value and what is
// expected).
std::optional<std::string> validate(const CuttingSettings& settings);

// The surface a blade edge sweeps over a stroke: the edge (heel, tip) at successive instants
// (scene, m); between instants i and i + 1 it covers the triangles (heel_i, tip_i, tip_i+1) and
// (heel_i, tip_i+1, heel_i+1). An element is cut once the stroke has passed all the way through
// it, however many instants that took, so a stroke keeps all its edges until it ends. Where the
// edge runs beside an earlier cut (CuttingSettings::groove_guide_m) it is bent onto that cut's
// surface, as it is now in the tissue, before the sweep is taken.
struct BladeStroke {
  std::vector<std::array<Eigen::Vector3d, 2>> edges_m;
  // The first instants' edges as they cut, heel to tip: bent onto the cut each ran beside when it
  // was taken (cut_stroke_so_far), so that the tissue's later motion does not move them. Instants
  // past these are bent when the stroke is cut.
  std::vector<std::vector<Eigen::Vector3d>> cutting_edges_m;
  // The instants an earlier cut of this stroke took in (cut_stroke_so_far sets it after each
  // update): what the stroke passed through before them was cut then, so a cut looks only at the
  // elements the stroke touched since (and a few instants before). 0: every element it touched.
  std::size_t settled_instants = 0;

  void add(const std::array<Eigen::Vector3d, 2>& edge_m) { edges_m.push_back(edge_m); }
  // A stroke of the one instant `edge_m`.
  void restart(const std::array<Eigen::Vector3d, 2>& edge_m) {
    edges_m.assign(1, edge_m);
    cutting_edges_m.clear();
    settled_instants = 0;
  }
  void clear() {
    edges_m.clear();
    cutting_edges_m.clear();
    settled_instants = 0;
  }
};

// The scalpel's edge (heel, tip) in the scene.
std::array<Eigen::Vector3d, 2> blade_edge_m(const Tool& scalpel);
// What a scalpel that has broken in cuts with: from the end of its shaft to the blade's tip. Taken
// deeper than its blade, the handle follows the blade into its incision and parts what it passes,
// as a longer blade would. (Pushing, the 5 mm shaft wedged the cut open, crushed the elements
// beside it and dragged light nodes that sprang back at metres per second: the explicit step fell
// to 0.05 ms, issue 42.)
std::array<Eigen::Vector3d, 2> cutting_edge_m(const Tool& scalpel);

// The blade's edge in the tissue: each stretch of the edge within an element (its faces pushed
// out by `margin_m`, so that an edge along faces, as in its own cut, is in; overlaps once), their
// length, and the force the crack front along them holds back, each stretch times its element's
// region's toughness: the work per unit advance of the crack (Mahvash & Hayward 2001); the
// friction on the blade's sides, each stretch times its region's blade friction; and
// whether the edge passes through an element or within about `reach_m` of one (its faces pushed
// out by that much). One walk over the nodes and one over the elements' corner indices; allocates
// nothing once `node_scratch` holds a byte per node (without it, a vector of its own).
struct EdgeInTissue {
  double length_m = 0.0;
  double resistance_n = 0.0;  // the crack front's: against the blade's motion across its edge
  double friction_n = 0.0;    // the sides': against the blade's motion in any direction
  bool within_reach = false;
};
// edge_in_tissue's margin unless told (m).
inline constexpr double kEdgeInTissueMarginM = 1e-6;
EdgeInTissue edge_in_tissue(const SimModel& model, const NodeArray& position_m,
                            const std::array<Eigen::Vector3d, 2>& edge_m, double reach_m = 0.0,
                            double margin_m = kEdgeInTissueMarginM,
                            std::vector<std::uint8_t>* node_scratch = nullptr);
// The length of the scalpel's edge in contact that `blade` (its part's contact) reports: the
// stretch of its axis that touched the tissue and the blade's thickness (a tip's crack is that
// wide). Times the toughness, the force at which it breaks in.
double blade_edge_in_contact_m(const PartContact& blade, const ToolGeometry& geometry);

struct CutReport {
  std::size_t elements_swept = 0;           // elements the sweep touches
  std::size_t elements_over_threshold = 0;  // of those, stressed past the cutting threshold
  std::size_t snapped_nodes = 0;
  std::size_t nodes_made_on_edges = 0;  // where no node could be moved (elements split on them)
  std::size_t elements_refined = 0;     // edges bisected to refine the mesh around the sweep
  std::size_t separated_faces = 0;
  std::size_t duplicated_nodes = 0;  // node copies made
  // Pieces that came free and were taken out (crumbs under min_free_body_volume_m3).
  std::size_t removed_elements = 0;
  std::size_t removed_nodes = 0;
  double removed_mass_kg = 0.0;
  // Pieces that came free and stay as bodies of their own (free_bodies).
  std::size_t freed_elements = 0;
  double freed_volume_m3 = 0.0;
  // Rest volume of the organ this cut parted from it, crumbs and bodies alike (what a body already
  // free loses to a cut is not counted again).
  double resected_volume_m3 = 0.0;
  // Flaps the cut left hanging by one face or none, with a corner of their own: merged into a
  // neighbour that takes their mass (cut_tissue step 6b); their rest volume.
  std::size_t merged_elements = 0;
  double merged_volume_m3 = 0.0;
  // The new model's added mass (SimModel::reference_element_height_m): elements a cut left thinner
  // than the mesh as built step no faster than it did.
  double added_mass_kg = 0.0;
};

struct CutResult {
  // Null when the sweep changed nothing (the old model and state stand). A refinement around the
  // sweep (refine_edge_m) stands even when nothing parted (report.separated_faces 0).
  std::shared_ptr<const SimModel> model;
  SimState state;
  // For each node and element of the new model, the one of the old model it came from (an
  // element split: each part; a node made on an edge: -1).
  std::vector<NodeIndex> node_origin;
  std::vector<TetIndex> element_origin;
  CutReport report;

  bool cut() const { return model != nullptr; }
};

// Cuts `model` in `state` along the stroke. Throws std::invalid_argument for invalid settings or
// a stroke that is not finite.
CutResult cut_tissue(const SimModel& model, const SimState& state, const BladeStroke& stroke,
                     const CuttingSettings& settings);

// At a stroke's end (the blade drawn out, or disarmed in the tissue), what its cut left joined
// within the cut's resolution (about an element) is parted:
// - holes in the cut (CuttingSettings::hole_angle_deg): interior faces lying in the cut's surface
//   with their three nodes on it;
// - a strand: a piece the stroke leaves joined to the organ only through at most kStrandFaces
//   faces, each of which the stroke's sweep reached (one of its two elements touches it). The
//   strand is the smallest set of faces between the tissue on the sweep's two sides (a maximum
//   flow over the elements' faces from the elements touching it on one side to those on the
//   other); the piece it frees holds no fixed node and is at least
//   CuttingSettings::min_free_body_volume_m3;
// - else, where another tool holds the tissue (`held_nodes`: the forceps' hold), a strand that
//   holds what it holds: the smallest set of faces, at most kStrandFaces, between the elements
//   holding a held node and those holding a fixed node, each near the cut (one of its two elements
//   touches the sweep or has a node on a cut face), freeing the held side. The hand that retracts
//   the lobe tells which side is the specimen, where the sweep's sides cannot: passes drawn a few
//   millimetres apart leave remnants between them inside the organ too, and the minimum cut
//   between the sides then ran through those (14–28 faces) while the lobe the forceps held hung
//   by 7 faces (issue 42).
// Where a resection's passes met, and around an element the cut left whole on one side (none of
// its crossings could be snapped or split), a resected lobe stayed on by 1 to 7 faces in some runs
// (issue 42). Nothing: nothing to part.
inline constexpr int kStrandFaces = 8;
CutResult part_remnants(const SimModel& model, const SimState& state, const BladeStroke& stroke,
                        const CuttingSettings& settings,
                        std::span<const NodeIndex> held_nodes = {});

// An update of a stroke as the blade goes on: its instants not yet bent are bent onto the cuts
// they run beside in the tissue as it is now (CuttingSettings::groove_guide_m), the stroke so far
// is cut, and its instants are settled for the next update.
// The real-time loop and bench-cut both update a stroke this way.
CutResult cut_stroke_so_far(const SimModel& model, const SimState& state, BladeStroke& stroke,
                            const CuttingSettings& settings);

// Von Mises equivalent of the Cauchy stress of element e in `state` (Pa): of the elastic part
// F·Fp⁻¹ in viscous regions (the instantaneous response, before the Maxwell arm relaxes).
double element_cutting_stress_pa(const SimModel& model, const SimState& state, std::size_t e);

// The largest angular frequency at rest of the model's free nodes among `nodes`, the other nodes
// held: power iteration on that block of M^(-1/2)·K·M^(-1/2), K the elements' stiffness (with
// average nodal pressure, its nodal volumetric energy). The block's largest eigenvalue is at most
// the whole mesh's (Cauchy interlacing); the modes a cut raises are local to the cut, so the block
// around it holds them, and a cut takes the larger of it and the model's old frequency.
double local_max_frequency_rad_per_s(const SimModel& model, const std::vector<NodeIndex>& nodes);

// That frequency and its mode: for each free node of the block, its share of the mode's kinetic
// energy (they sum to 1).
struct LocalMode {
  double frequency_rad_per_s = 0.0;
  std::vector<NodeIndex> node;
  std::vector<double> energy_share;
};
LocalMode local_top_mode(const SimModel& model, const std::vector<NodeIndex>& nodes);

// Selective mass scaling: adds mass to the free nodes among `nodes` (node_added_mass_kg) until the
// block's highest frequency is at most `ceiling_rad_per_s` (to a part in a thousand), each time to
// the nodes the top mode moves most (at least half the largest displacement), by the factor that
// brings that mode's Rayleigh quotient to the ceiling, but never past `max_added_mass_fraction` of
// the tissue's mass in all; then the model's frequency (the block's, if higher) and stable step.
// Returns the mass added (kg). Given the nodes' velocities, a node given mass keeps its momentum
// (slows), so the mass brings no energy. A cut calls it with the frequency of the model it cut, so
// that its small parts do not lower the explicit step.
double scale_masses_to_frequency(SimModel& model, const std::vector<NodeIndex>& nodes,
                                 double ceiling_rad_per_s, double max_added_mass_fraction,
                                 NodeArray* velocity_m_per_s = nullptr);

// The bodies a cut freed: the model's connected pieces that hold no fixed node (of a model with
// none, every piece but the largest, the organ). Each its elements, ascending, and rest volume.
struct FreeBody {
  std::vector<TetIndex> elements;
  double rest_volume_m3 = 0.0;
};
std::vector<FreeBody> free_bodies(const SimModel& model);
// Per element: 1 in the organ (not in a free body).
std::vector<std::uint8_t> organ_elements(const SimModel& model);

// The model and state without the free body holding `element` (its nodes and elements; the others
// keep their order, mass, added mass and history; the stable step stays, as removing a body that
// shares no node with the rest leaves the rest's frequencies as they were). The report counts it as
// removed (not resected again). Throws std::invalid_argument when `element` is not in a free body.
CutResult take_out_body(const SimModel& model, const SimState& state, TetIndex element);

// The mesh of a model (rest positions, elements, regions), e.g. to extract its surface.
TetMesh model_mesh(const SimModel& model);

// The model's boundary: read off its boundary-face marks once it has been cut (no hashing of
// every face), else extract_surface of its mesh. The same triangles either way (their order
// differs).
BoundarySurface boundary_surface(const SimModel& model);

// Which triangles of `surface` (extracted from the model's mesh) are faces made by cuts (shown as
// the tissue's interior), one flag per triangle.
std::vector<std::uint8_t> cut_face_flags(const SimModel& model, const BoundarySurface& surface);

}  // namespace liversim
