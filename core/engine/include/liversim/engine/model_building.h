#pragma once
// Building the constant model from a mesh and its options, and changing its materials live: both
// end with the model's stable explicit step, so they sit above the force loops and the integrators
// (model.h, the model itself, below them).

#include "liversim/engine/model.h"
#include "liversim/engine/tet_mesh.h"

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace liversim {

// Builds the model. Throws std::invalid_argument naming the problem for an invalid material, a
// region without a material, a fibre field of the wrong size or with a zero vector, an empty mesh,
// an inverted or zero-volume element, a fixed node index out of range, or integrator settings out
// of range.
SimModel build_model(const TetMesh& mesh, const ModelOptions& options);

// Gives the model's regions these materials (a live change of the tissue, also of a cut model):
// every per-element modulus, fibre and viscous parameter, the masses (a cut model's element masses
// scale with the density), the effects they switch on and the stable step follow, as build_model
// would make them. A region with fibres needs the model to have fibre directions already. Throws
// std::invalid_argument as build_model does for the materials; the model is then unchanged only
// if the throw came from validation (callers change a copy).
void set_region_materials(SimModel& model, const std::vector<RegionMaterial>& regions);

// Each node's lumped mass, a quarter of each of its elements' (element_mass_kg, or density times
// rest volume before a cut) and its added mass (node_added_mass_kg), the total added, and the
// inverse masses (0 on fixed nodes and on nodes no element holds).
void lump_node_masses(SimModel& model);
// The tissue's mass: the lumped masses less what the mass scaling added (kg).
double tissue_mass_kg(const SimModel& model);

// Switches gravity on with this acceleration (m/s², the mesh's axes; zero: off) and the support
// the organ rests on (null: none), as build_model would make them, also on a cut model: the
// support's stiffness follows the model's largest frequency, and the stable step follows both.
// With gravity and a region that yields, the in-vivo stress is measured (in_vivo_stress.h: the
// organ settles for 2 s of simulated time on the calling thread).
// Throws std::invalid_argument for an acceleration that is not finite.
void set_gravity(SimModel& model, const Eigen::Vector3d& gravity_m_per_s2,
                 std::shared_ptr<const SupportSurface> support);

}  // namespace liversim
