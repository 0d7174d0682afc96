#include "liversim/engine/model_building.h"

#include "liversim/engine/in_vivo_stress.h"
#include "liversim/engine/validation_message.h"

#include "liversim/engine/integrator.h"
#include "liversim/engine/mesh_quality.h"

#include <Eigen/Dense>

#include <cmath>
#include <stdexcept>
#include <string>

namespace liversim {

namespace {

std::string region_name(std::size_t r) {
  return r == 0 ? "region 0 (parenchyma)" : "region " + std::to_string(r);
}

void validate_regions(const std::vector<RegionMaterial>& regions) {
  if (regions.empty()) throw std::invalid_argument("no region materials given");
  for (std::size_t r = 0; r < regions.size(); ++r) {
    if (auto problem = validate(regions[r].tissue))
      throw std::invalid_argument(region_name(r) + ": " + *problem);
    if (regions[r].fibres)
      if (auto problem = validate(*regions[r].fibres))
        throw std::invalid_argument(region_name(r) + ": " + *problem);
    if (const double j = regions[r].fracture_toughness_j_per_m2; !std::isfinite(j) || j < 0.0)
      throw std::invalid_argument(
          region_name(r) + ": " +
          out_of_range_message("fracture toughness (J/m²)", j, "a finite value >= 0"));
    if (const double f = regions[r].blade_friction_n_per_m; !std::isfinite(f) || f < 0.0)
      throw std::invalid_argument(
          region_name(r) + ": " +
          out_of_range_message("blade friction (N/m)", f, "a finite value >= 0"));
    if (regions[r].viscoplastic && !regions[r].viscoelastic)
      throw std::invalid_argument(region_name(r) +
                                  ": viscoplasticity needs the viscoelastic parameters (E1, E2, "
                                  "eta1) it acts in series with");
    if (const auto& visco = regions[r].viscoelastic) {
      // The viscous law's elastic base is Neo-Hookean; an I2 term would be ignored by its forces
      // but not by the model's moduli (and the energy books read those).
      if (regions[r].tissue.mooney_rivlin_fraction > 0.0)
        throw std::invalid_argument(region_name(r) +
                                    ": a Mooney-Rivlin fraction > 0 is not available with "
                                    "viscoelasticity (its elastic base is Neo-Hookean)");
      if (auto problem = validate(ViscousTissueParameters{*visco, regions[r].tissue.poisson_ratio,
                                                          regions[r].viscoplastic}))
        throw std::invalid_argument(region_name(r) + ": " + *problem);
      const double instantaneous = visco->instantaneous_modulus_pa();
      if (std::abs(instantaneous - regions[r].tissue.youngs_modulus_pa) > 1e-9 * instantaneous)
        throw std::invalid_argument(
            region_name(r) + ": Young's modulus " +
            std::to_string(regions[r].tissue.youngs_modulus_pa) +
            " Pa must equal the instantaneous modulus E1 + E2 = " + std::to_string(instantaneous) +
            " Pa of its viscoelastic parameters");
    }
  }
}

// Per-element unit directions of one family from a field that is empty, uniform or per element.
std::vector<Eigen::Vector3d> fibre_directions(const std::vector<Eigen::Vector3d>& field,
                                              std::size_t tets, const char* family) {
  if (field.empty()) return std::vector<Eigen::Vector3d>(tets, Eigen::Vector3d::Zero());
  if (field.size() != 1 && field.size() != tets)
    throw std::invalid_argument(std::string(family) + " fibre field has " +
                                std::to_string(field.size()) + " directions; expected 1 or " +
                                std::to_string(tets) + " (one per element)");
  std::vector<Eigen::Vector3d> directions(tets);
  for (std::size_t e = 0; e < tets; ++e) {
    const Eigen::Vector3d& a = field[field.size() == 1 ? 0 : e];
    if (!a.allFinite() || a.norm() < 1e-12)
      throw std::invalid_argument(std::string(family) + " fibre direction of element " +
                                  std::to_string(field.size() == 1 ? 0 : e) +
                                  " is zero or not a number");
    directions[e] = a.normalized();
  }
  return directions;
}

}  // namespace

SimModel build_model(const TetMesh& mesh, const ModelOptions& options) {
  validate_regions(options.regions);
  if (mesh.tet_count() == 0) throw std::invalid_argument("the mesh has no tetrahedra");
  if (!(options.mass_damping_per_s >= 0.0) || !std::isfinite(options.mass_damping_per_s))
    throw std::invalid_argument("mass damping must be a finite value >= 0 (1/s)");
  if (!(options.stable_step_safety > 0.0 && options.stable_step_safety <= 1.0))
    throw std::invalid_argument("stable step safety factor must be in (0, 1]");
  if (!(options.plastic_flow_interval_s >= 0.0) || !std::isfinite(options.plastic_flow_interval_s))
    throw std::invalid_argument("the plastic flow's interval must be a finite time ≥ 0 (s)");
  if (!options.gravity_m_per_s2.allFinite())
    throw std::invalid_argument("gravity must be a finite acceleration (m/s²)");
  if (!(options.support_frequency_fraction > 0.0 && options.support_frequency_fraction <= 1.0))
    throw std::invalid_argument("the support's frequency fraction must be in (0, 1]");
  if (!(options.support_damping_ratio >= 0.0) || !std::isfinite(options.support_damping_ratio))
    throw std::invalid_argument("the support's damping ratio must be a finite value ≥ 0");
  if (!(options.support_friction_coefficient >= 0.0) ||
      !std::isfinite(options.support_friction_coefficient))
    throw std::invalid_argument("the support's friction coefficient must be a finite value ≥ 0");
  validate_integrator(options.integrator);

  SimModel model;
  model.node_count = mesh.node_count();
  model.tet_count = mesh.tet_count();
  model.corner = mesh.corner;
  model.rest_position_m = mesh.rest_position_m;
  model.mass_damping_per_s = options.mass_damping_per_s;
  model.stable_step_safety = options.stable_step_safety;
  model.plastic_flow_interval_s = options.plastic_flow_interval_s;
  model.integrator = options.integrator;
  // Gravity and the support are set with the stable step, at the end (set_gravity).
  model.gravity_m_per_s2 = options.gravity_m_per_s2;
  model.support = options.support;
  model.support_frequency_fraction = options.support_frequency_fraction;
  model.support_damping_ratio = options.support_damping_ratio;
  model.support_friction_coefficient = options.support_friction_coefficient;

  const std::size_t tets = model.tet_count;
  for (auto& entry : model.dm_inverse) entry.resize(tets);
  model.rest_volume_m3.resize(tets);
  model.region.assign(tets, 0);

  for (std::size_t e = 0; e < tets; ++e) {
    const auto region = e < mesh.region.size() ? mesh.region[e] : 0;
    if (region < 0 || static_cast<std::size_t>(region) >= options.regions.size())
      throw std::invalid_argument("element " + std::to_string(e) + " is in region " +
                                  std::to_string(region) + ", which has no material (" +
                                  std::to_string(options.regions.size()) + " regions given)");
    model.region[e] = region;

    const auto nodes = mesh.tet(e);
    for (auto n : nodes) {
      if (n < 0 || static_cast<std::size_t>(n) >= model.node_count)
        throw std::invalid_argument("element " + std::to_string(e) + " refers to node " +
                                    std::to_string(n) + ", outside the mesh");
    }
    const Eigen::Vector3d x0 = mesh.rest_position_m.at(nodes[0]);
    Eigen::Matrix3d dm;
    for (int c = 1; c < 4; ++c) dm.col(c - 1) = mesh.rest_position_m.at(nodes[c]) - x0;
    const double volume = dm.determinant() / 6.0;
    const double scale = dm.colwise().norm().maxCoeff();
    if (!(volume > 1e-12 * scale * scale * scale))
      throw std::invalid_argument("element " + std::to_string(e) +
                                  (volume < 0 ? " is inverted" : " has zero volume") +
                                  " in the rest configuration");
    const Eigen::Matrix3d inv = dm.inverse();
    for (int k = 0; k < 9; ++k) model.dm_inverse[k][e] = inv(k / 3, k % 3);
    model.rest_volume_m3[e] = volume;
  }

  bool fibres = false;
  for (const auto& region : options.regions)
    fibres |= region.fibres.has_value() && region.fibres->k1_pa > 0.0;
  if (fibres) {
    if (options.fibre_field.first_family.empty())
      throw std::invalid_argument("a region has fibres but the fibre field gives no direction");
    model.fibre_direction[0] = fibre_directions(options.fibre_field.first_family, tets, "first");
    model.fibre_direction[1] = fibre_directions(options.fibre_field.second_family, tets, "second");
  }
  model.effects.average_nodal_pressure = options.average_nodal_pressure;

  model.is_fixed.assign(model.node_count, 0);
  for (auto n : options.fixed_nodes) {
    if (n < 0 || static_cast<std::size_t>(n) >= model.node_count)
      throw std::invalid_argument("fixed node " + std::to_string(n) + " is outside the mesh (" +
                                  std::to_string(model.node_count) + " nodes)");
    model.is_fixed[n] = 1;
  }
  model.min_element_height_m = assess_quality(mesh).min_height_m;
  model.reference_element_height_m = model.min_element_height_m;
  build_node_incidence(model);
  set_region_materials(model, options.regions);
  return model;
}

void set_region_materials(SimModel& model, const std::vector<RegionMaterial>& regions) {
  validate_regions(regions);
  const std::size_t tets = model.tet_count;
  for (std::size_t e = 0; e < tets; ++e)
    if (model.region[e] < 0 || static_cast<std::size_t>(model.region[e]) >= regions.size())
      throw std::invalid_argument("element " + std::to_string(e) + " is in region " +
                                  std::to_string(model.region[e]) + ", which has no material (" +
                                  std::to_string(regions.size()) + " regions given)");
  bool fibres = false;
  for (const auto& region : regions)
    fibres |= region.fibres.has_value() && region.fibres->k1_pa > 0.0;
  if (fibres && model.fibre_direction[0].size() != tets)
    throw std::invalid_argument("a region has fibres but the model has no fibre directions");

  // A cut model keeps each element's mass through the cut (not density times rest volume): a new
  // density scales it.
  if (!model.element_mass_kg.empty())
    for (std::size_t e = 0; e < tets; ++e)
      model.element_mass_kg[e] *= regions[model.region[e]].tissue.density_kg_per_m3 /
                                  model.regions[model.region[e]].tissue.density_kg_per_m3;
  model.regions = regions;

  model.shear_modulus_pa.resize(tets);
  model.lame_lambda_pa.resize(tets);
  for (std::size_t e = 0; e < tets; ++e) {
    const TissueMaterial& tissue = regions[model.region[e]].tissue;
    model.shear_modulus_pa[e] = (1.0 - tissue.mooney_rivlin_fraction) * tissue.shear_modulus_pa();
    model.lame_lambda_pa[e] = tissue.lame_lambda_pa();
  }
  lump_node_masses(model);

  model.effects.fibres = fibres;
  model.fibre_parameters.clear();
  if (fibres) {
    model.fibre_parameters.resize(tets);
    for (std::size_t e = 0; e < tets; ++e)
      model.fibre_parameters[e] = regions[model.region[e]].fibres.value_or(FibreParameters{});
  }

  model.effects.mooney_rivlin = false;
  for (const auto& region : regions)
    model.effects.mooney_rivlin |= region.tissue.mooney_rivlin_fraction > 0.0;
  model.mooney_rivlin_c2_pa.clear();
  if (model.effects.mooney_rivlin) {
    model.mooney_rivlin_c2_pa.resize(tets);
    for (std::size_t e = 0; e < tets; ++e) {
      const TissueMaterial& tissue = regions[model.region[e]].tissue;
      model.mooney_rivlin_c2_pa[e] =
          0.5 * tissue.mooney_rivlin_fraction * tissue.shear_modulus_pa();
      // The I2 term adds 4 c2 to the small-strain λ; take it off so E and ν mean what they say.
      model.lame_lambda_pa[e] -= 4.0 * model.mooney_rivlin_c2_pa[e];
    }
  }
  model.effects.viscous = false;
  for (const auto& region : regions) model.effects.viscous |= region.viscoelastic.has_value();
  model.viscous_parameters.clear();
  if (model.effects.viscous)
    for (const auto& region : regions)
      model.viscous_parameters.push_back(
          region.viscoelastic
              ? std::optional<ViscousTissueParameters>(ViscousTissueParameters{
                    *region.viscoelastic, region.tissue.poisson_ratio, region.viscoplastic})
              : std::nullopt);

  model.max_frequency_rad_per_s = estimate_max_frequency_rad_per_s(model, model.rest_position_m);
  model.uncut_frequency_rad_per_s = model.max_frequency_rad_per_s;
  set_gravity(model, model.gravity_m_per_s2, model.support);
}

void lump_node_masses(SimModel& model) {
  model.lumped_mass_kg.assign(model.node_count, 0.0);
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    const double corner_mass_kg =
        (model.element_mass_kg.empty()
             ? model.regions[model.region[e]].tissue.density_kg_per_m3 * model.rest_volume_m3[e]
             : model.element_mass_kg[e]) /
        4.0;
    for (int c = 0; c < 4; ++c) model.lumped_mass_kg[model.corner[c][e]] += corner_mass_kg;
  }
  model.added_mass_kg = 0.0;
  if (!model.node_added_mass_kg.empty())
    for (std::size_t n = 0; n < model.node_count; ++n) {
      model.lumped_mass_kg[n] += model.node_added_mass_kg[n];
      model.added_mass_kg += model.node_added_mass_kg[n];
    }
  model.inverse_mass_per_kg.resize(model.node_count);
  for (std::size_t n = 0; n < model.node_count; ++n) {
    // A node no element touches has no mass; keep it still rather than divide by zero.
    const bool free = !model.is_fixed[n] && model.lumped_mass_kg[n] > 0.0;
    model.inverse_mass_per_kg[n] = free ? 1.0 / model.lumped_mass_kg[n] : 0.0;
  }
}

double tissue_mass_kg(const SimModel& model) {
  double total_kg = -model.added_mass_kg;
  for (double m : model.lumped_mass_kg) total_kg += m;
  return total_kg;
}

void set_gravity(SimModel& model, const Eigen::Vector3d& gravity_m_per_s2,
                 std::shared_ptr<const SupportSurface> support) {
  if (!gravity_m_per_s2.allFinite())
    throw std::invalid_argument("gravity must be a finite acceleration (m/s²)");
  model.gravity_m_per_s2 = gravity_m_per_s2;
  model.effects.gravity = !gravity_m_per_s2.isZero(0.0);
  model.support = std::move(support);
  // The support's contact frequency follows the mesh's: a stiffer tissue, a stiffer support.
  const double support_omega = model.support_frequency_fraction * model.max_frequency_rad_per_s;
  model.support_stiffness_per_kg = model.support ? support_omega * support_omega : 0.0;
  model.stable_time_step_s = stable_time_step_s(model, StepInputs{});
  // The yield is measured above the stress the organ bears under its weight (in_vivo_stress.h).
  model.in_vivo_stress_pa.clear();  // (the settling copies the model: not the old stress too)
  model.in_vivo_stress_pa = in_vivo_stress_pa(model);
}

}  // namespace liversim
