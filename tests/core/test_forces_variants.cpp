// The builds of the force loops without an effect (the benchmark's measure of what an effect that
// is off costs) compute the tissue's forces as the normal build does on a scene without that
// effect, and refuse a scene that has it on. Gravity's build leaves out the weight and the support.
#include "block_mesh.h"

#include "liversim/engine/forces.h"
#include "liversim/engine/model_building.h"
#include "liversim/engine/support.h"
#include "liversim/engine/surface.h"
#include "liversim/studies/forces_variants.h"

#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>

namespace liversim {
namespace {

ModelOptions full_options(const TetMesh& mesh) {
  ModelOptions options;
  options.regions[0].tissue = TissueMaterial{3500.0, 0.45, 1060.0};
  options.regions[0].viscoelastic = ViscoelasticParameters{2000.0, 1500.0, 400.0};
  options.regions[0].viscoplastic = ViscoplasticParameters{20.0, 500.0, 0.5};
  options.regions[0].fibres = FibreParameters{1000.0, 2.0};
  options.fibre_field.first_family = {Eigen::Vector3d(1.0, 0.2, 0.0)};
  options.average_nodal_pressure = true;
  options.gravity_m_per_s2 = {0.0, 0.0, -9.81};
  options.support =
      std::make_shared<const SupportSurface>(support_under(mesh, options.gravity_m_per_s2));
  return options;
}

ModelOptions without(const TetMesh& mesh, unsigned effect) {
  ModelOptions options = full_options(mesh);
  if (effect == kWithoutFibres) {
    options.regions[0].fibres.reset();
    options.fibre_field = {};
  }
  if (effect == kWithoutViscous) {
    options.regions[0].viscoelastic.reset();
    options.regions[0].viscoplastic.reset();
  }
  if (effect == kWithoutAverageNodalPressure) options.average_nodal_pressure = false;
  if (effect == kWithoutGravity) {
    options.gravity_m_per_s2.setZero();
    options.support.reset();
  }
  return options;  // (the full scene has no Mooney–Rivlin term)
}

TEST(ForcesVariants, EachBuildMatchesTheNormalOneWithoutItsEffectAndRefusesIt) {
  const TetMesh mesh = testing::block_mesh(6, 4, 4, {0.03, 0.02, 0.02}, 0.2);
  ASSERT_EQ(forces_variants().size(), 5u);
  for (const ForcesVariant& variant : forces_variants()) {
    const SimModel model = build_model(mesh, without(mesh, variant.without));
    SimState normal = make_rest_state(model), variant_state = make_rest_state(model);
    // Stretched, and sunk 1 mm into the support where it has one.
    for (std::size_t n = 0; n < model.node_count; ++n) {
      const Eigen::Vector3d rest = model.rest_position_m.at(n);
      normal.position_m.set(n, rest + Eigen::Vector3d(0.2 * rest.x(), -0.04 * rest.y(), -1e-3));
    }
    variant_state.position_m = normal.position_m;
    for (int step = 0; step < 3; ++step) {  // a viscous history builds up over the steps
      compute_tissue_forces(model, normal, 0.01);
      variant.compute_tissue_forces(model, variant_state, 0.01);
    }
    // The same source and the same operations: equal to the last bit.
    EXPECT_EQ(normal.force_n.x, variant_state.force_n.x) << variant.effect;
    EXPECT_EQ(normal.force_n.z, variant_state.force_n.z) << variant.effect;

    if (variant.without == kWithoutMooneyRivlin) {
      ModelOptions options = without(mesh, 0);
      options.regions[0] = RegionMaterial{};
      options.regions[0].tissue = TissueMaterial{3500.0, 0.45, 1060.0, 0.3};
      options.fibre_field = {};
      const SimModel mooney = build_model(mesh, options);
      SimState state = make_rest_state(mooney);
      EXPECT_THROW(variant.compute_tissue_forces(mooney, state, 0.01), std::invalid_argument);
    } else {
      const SimModel full = build_model(mesh, full_options(mesh));
      SimState state = make_rest_state(full);
      EXPECT_THROW(variant.compute_tissue_forces(full, state, 0.01), std::invalid_argument)
          << variant.effect;
    }
  }
}

}  // namespace
}  // namespace liversim
