#pragma once
// The force loops, included by forces.cpp (the engine's build, with every effect) and by
// core/studies/variants/force_loops_variant.cpp (builds without one effect each, for the
// benchmark). LIVERSIM_FORCES_VARIANT names a build's namespace and LIVERSIM_FORCES_WITHOUT is
// its mask of kWithout* bits; unset, this is the engine's build.

#include "liversim/engine/forces.h"
#include "liversim/engine/in_vivo_stress.h"

#include "liversim/engine/state.h"
#include "liversim/engine/support.h"

#include "element_kernels.h"
#include "force_loop_bits.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <type_traits>

#ifdef LIVERSIM_FORCES_VARIANT
#define LIVERSIM_FORCES_NAMESPACE liversim::LIVERSIM_FORCES_VARIANT
#else
#define LIVERSIM_FORCES_NAMESPACE liversim
#define LIVERSIM_FORCES_WITHOUT 0
#endif

namespace LIVERSIM_FORCES_NAMESPACE {
// Calls within this file name this build's functions: unqualified, argument-dependent lookup
// would also find the normal build's (namespace liversim) in a variant.
namespace here = LIVERSIM_FORCES_NAMESPACE;
namespace {

constexpr unsigned kWithout = LIVERSIM_FORCES_WITHOUT;
constexpr bool kBuiltFibres = !(kWithout & force_loop_bits::fibres);
constexpr bool kBuiltViscous = !(kWithout & force_loop_bits::viscous);
constexpr bool kBuiltAveragedPressure = !(kWithout & force_loop_bits::average_nodal_pressure);
constexpr bool kBuiltMooneyRivlin = !(kWithout & force_loop_bits::mooney_rivlin);
constexpr bool kBuiltGravity = !(kWithout & force_loop_bits::gravity);

// The model's effects that this build contains (the others are constant false, so the compiler
// drops their branches).
EffectSet built(const SimModel& model) {
  EffectSet on = model.effects;
  on.fibres = kBuiltFibres && on.fibres;
  on.viscous = kBuiltViscous && on.viscous;
  on.average_nodal_pressure = kBuiltAveragedPressure && on.average_nodal_pressure;
  on.mooney_rivlin = kBuiltMooneyRivlin && on.mooney_rivlin;
  on.gravity = kBuiltGravity && on.gravity;
  return on;
}

// A build without an effect refuses a model that has it rather than compute something else.
void require_built(const SimModel& model) {
  if constexpr (kWithout != 0) {
    const EffectSet& on = model.effects;
    if ((on.fibres && !kBuiltFibres) || (on.viscous && !kBuiltViscous) ||
        (on.average_nodal_pressure && !kBuiltAveragedPressure) ||
        (on.mooney_rivlin && !kBuiltMooneyRivlin) || (on.gravity && !kBuiltGravity))
      throw std::invalid_argument(
          "this build of the force loops does not contain an effect the "
          "model has on");
  }
}

}  // namespace

Eigen::Matrix3d element_dm_inverse(const SimModel& model, std::size_t e) {
  Eigen::Matrix3d m;
  for (int k = 0; k < 9; ++k) m(k / 3, k % 3) = model.dm_inverse[k][e];
  return m;
}

namespace {

Eigen::Matrix3d deformed_edges(const SimModel& model, const NodeArray& x, std::size_t e) {
  const auto n0 = model.corner[0][e];
  Eigen::Matrix3d ds;
  for (int c = 1; c < 4; ++c) {
    const auto n = model.corner[c][e];
    ds.col(c - 1) = Eigen::Vector3d(x.x[n] - x.x[n0], x.y[n] - x.y[n0], x.z[n] - x.z[n0]);
  }
  return ds;
}

}  // namespace

Eigen::Matrix3d deformation_gradient(const SimModel& model, const NodeArray& position,
                                     std::size_t e) {
  return deformed_edges(model, position, e) * here::element_dm_inverse(model, e);
}

namespace {

// History-dependent materials of one evaluation: the state to advance and commit, and the step
// constants per region; null when the model has no viscous region.
struct ViscousContext {
  ViscousHistory* history;
  const std::vector<std::optional<ViscousTissueStep>>* step_by_region;
  const ViscousArmInputs* arm = nullptr;  // set: the arm is carried by the integrator
  double* dissipated_j = nullptr;         // committing: the dashpots' work of the step is added
};

bool in_viscous_region(const SimModel& model, std::size_t e) {
  return built(model).viscous &&
         model.viscous_parameters[static_cast<std::size_t>(model.region[e])].has_value();
}

// `averaged_lambda_pressure` is used only with average nodal pressure (kAveragedPressure).
template <bool kFibres, bool kViscous, bool kAveragedPressure, bool kMooneyRivlin>
Eigen::Matrix3d stress_of(const SimModel& model, std::size_t e, const Eigen::Matrix3d& F,
                          double averaged_lambda_pressure, ElasticEvaluation& seen,
                          const ViscousContext& viscous) {
  Eigen::Matrix3d P;
  const auto* step = kViscous ? &(*viscous.step_by_region)[model.region[e]] : nullptr;
  if (kViscous && step->has_value()) {
    if (viscous.arm) {
      const ViscousArmInputs& arm = *viscous.arm;
      const auto r = static_cast<std::size_t>(model.region[e]);
      P = viscoelastic_stress_rate_form(F, **step, viscous.history->inverse_plastic_deformation(e),
                                        arm.q_known[e], arm.keep_by_region[r],
                                        arm.elastic_weight_by_region[r], arm.elastic_stress[e]);
    } else {
      // The history committed here spans the step: book its dashpots' work (trapezoid of 2ψ/τ).
      const ViscousTissueStep& s = **step;
      ViscousTissueState history = viscous.history->load(e);
      const double before = maxwell_arm_energy_density(history.maxwell_stress_pa, s);
      P = viscous_tissue_update(F, s, history, yield_raise_pa(model, e));
      viscous.history->store(e, history);
      *viscous.dissipated_j += model.rest_volume_m3[e] * s.dt_s / s.relaxation_time_s *
                               (before + maxwell_arm_energy_density(history.maxwell_stress_pa, s));
    }
  } else if (kAveragedPressure && !in_viscous_region(model, e))
    // A viscous region's law works with its element's own volume ratio, so its instantaneous
    // elastic response (what the stable step is estimated from) must too.
    P = neo_hookean::first_piola_stress_given_lambda_pressure(
        F, model.shear_modulus_pa[e], model.lame_lambda_pa[e], averaged_lambda_pressure);
  else
    P = neo_hookean::first_piola_stress(F, model.shear_modulus_pa[e], model.lame_lambda_pa[e]);
  if constexpr (kMooneyRivlin)
    if (!(kViscous && step->has_value()))
      P += mooney_rivlin::extra_first_piola_stress(F, model.mooney_rivlin_c2_pa[e]);
  if constexpr (kFibres) {
    const FibreParameters& fibres = model.fibre_parameters[e];
    for (const auto& family : model.fibre_direction) {
      const Eigen::Vector3d& a = family[e];
      P += hgo::first_piola_stress(F, a, fibres);
      seen.max_fibre_modulus_pa =
          std::max(seen.max_fibre_modulus_pa, hgo::tangent_modulus_pa(F, a, fibres));
    }
  }
  return P;
}

// Runs body(begin, end, chunk) over [0, items) in chunks of `per`, on the scratch's workers.
template <typename Body>
void for_each_chunk(const ForceScratch& scratch, std::size_t items, std::size_t per, Body&& body) {
  const std::size_t chunks = (items + per - 1) / per;
  auto task = [&](std::size_t c) { body(c * per, std::min(items, (c + 1) * per), c); };
  if (scratch.workers)
    scratch.workers->run(chunks, task);
  else
    for (std::size_t c = 0; c < chunks; ++c) task(c);
}

detail::ElasticKernelData kernel_data(const SimModel& model, const NodeArray& position,
                                      ForceScratch& scratch) {
  detail::ElasticKernelData d{};
  for (int c = 0; c < 4; ++c) d.corner[c] = model.corner[c].data();
  d.x = position.x.data();
  d.y = position.y.data();
  d.z = position.z.data();
  for (int k = 0; k < 9; ++k) d.dm_inverse[k] = model.dm_inverse[k].data();
  d.rest_volume_m3 = model.rest_volume_m3.data();
  d.shear_modulus_pa = model.shear_modulus_pa.data();
  d.lame_lambda_pa = model.lame_lambda_pa.data();
  d.nodal_lambda_pressure_pa = scratch.nodal_lambda_pressure_pa.data();
  if (built(model).fibres) {
    static_assert(sizeof(FibreParameters) == 2 * sizeof(double));
    static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double));
    d.fibre_parameters = &model.fibre_parameters.data()->k1_pa;
    int families = 0;  // the families present, first ones first
    for (const auto& family : model.fibre_direction)
      if (!family.empty()) d.fibre_direction[families++] = family[0].data();
  }
  const std::size_t tets = model.tet_count;
  for (int c = 0; c < 4; ++c) {
    d.corner_force[c][0] = scratch.corner_force_n.x.data() + c * tets;
    d.corner_force[c][1] = scratch.corner_force_n.y.data() + c * tets;
    d.corner_force[c][2] = scratch.corner_force_n.z.data() + c * tets;
  }
  d.volume_ratio = scratch.element_volume_ratio.data();
  return d;
}

// Average nodal pressure, first pass: each node's volume-weighted mean J̄ of its elements' J and
// the λ part of the pressure there, p_λ̄(J̄) with λ̄ the volume-weighted mean of their λ. Elements
// of viscous regions keep their own J and take no part. Each element then takes the mean of its
// corners' p_λ̄(J̄): the exact gradient of the nodal energy Σ_n V_n/4·W_λ̄(J̄) (energy.cpp), also
// where λ jumps between regions (p_λ(mean of the corners' J̄) with the element's own λ is not, and
// creates energy at a stiff lesion's boundary).
void average_nodal_volume_ratios(const SimModel& model, const detail::ElasticKernelData& data,
                                 ForceScratch& scratch) {
  const auto volume_ratio = detail::elastic_kernels().volume_ratio;
  for_each_chunk(
      scratch, model.tet_count, kElementsPerChunk,
      [&](std::size_t begin, std::size_t end, std::size_t) { volume_ratio(data, begin, end); });
  for_each_chunk(
      scratch, model.node_count, kNodesPerChunk,
      [&](std::size_t begin, std::size_t end, std::size_t chunk) {
        double min_j = std::numeric_limits<double>::infinity();
        for (std::size_t n = begin; n < end; ++n) {
          double weighted = 0.0, volume = 0.0, lambda_volume = 0.0;
          for (auto s = model.node_slot_begin[n]; s < model.node_slot_begin[n + 1]; ++s) {
            const auto e = static_cast<std::size_t>(model.node_slot_element[s]);
            if (in_viscous_region(model, e)) continue;
            weighted += model.rest_volume_m3[e] * scratch.element_volume_ratio[e];
            volume += model.rest_volume_m3[e];
            lambda_volume += model.rest_volume_m3[e] * model.lame_lambda_pa[e];
          }
          if (volume > 0.0) min_j = std::min(min_j, weighted / volume);
          scratch.nodal_lambda_pressure_pa[n] =
              volume > 0.0 ? neo_hookean::lambda_pressure(weighted / volume, lambda_volume / volume)
                           : 0.0;
        }
        scratch.chunk_min_nodal_volume_ratio[chunk] = min_j;
      });
  scratch.min_nodal_volume_ratio = std::numeric_limits<double>::infinity();
  for (double min_j : scratch.chunk_min_nodal_volume_ratio)
    scratch.min_nodal_volume_ratio = std::min(scratch.min_nodal_volume_ratio, min_j);
}

ElasticEvaluation nothing_seen() {
  return {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(), 0.0,
          std::numeric_limits<double>::infinity()};
}
detail::ElasticKernelSeen kernel_nothing_seen() {
  const ElasticEvaluation none = nothing_seen();
  return {none.min_volume_ratio, none.max_volume_ratio, none.max_fibre_modulus_pa};
}
ElasticEvaluation evaluation_of(const detail::ElasticKernelSeen& seen) {
  return {seen.min_volume_ratio, seen.max_volume_ratio, seen.max_fibre_modulus_pa,
          std::numeric_limits<double>::infinity()};
}

// Fibre families present in the kernel data (kernel_data puts them first).
int fibre_families(const detail::ElasticKernelData& data) {
  return (data.fibre_direction[0] != nullptr) + (data.fibre_direction[1] != nullptr);
}

// One element of the general loop: its forces into the corner slots, what it saw into `seen`.
template <bool kFibres, bool kViscous, bool kAveragedPressure, bool kMooneyRivlin>
void general_element(const SimModel& model, const NodeArray& position, ForceScratch& scratch,
                     const ViscousContext& viscous, std::size_t e, ElasticEvaluation& seen) {
  auto& corner_scratch = scratch.corner_force_n;
  const Eigen::Matrix3d dm_inv = here::element_dm_inverse(model, e);
  const Eigen::Matrix3d F = deformed_edges(model, position, e) * dm_inv;
  const double J = F.determinant();
  seen.min_volume_ratio = std::min(seen.min_volume_ratio, J);
  seen.max_volume_ratio = std::max(seen.max_volume_ratio, J);
  double averaged = 0.0;  // the λ part of the pressure, with average nodal pressure
  if constexpr (kAveragedPressure)
    for (int c = 0; c < 4; ++c)
      averaged += 0.25 * scratch.nodal_lambda_pressure_pa[model.corner[c][e]];
  const Eigen::Matrix3d P = stress_of<kFibres, kViscous, kAveragedPressure, kMooneyRivlin>(
      model, e, F, averaged, seen, viscous);
  // Nodal forces of corners 1..3 are the columns of −V·P·Dm⁻ᵀ; corner 0 balances them.
  const Eigen::Matrix3d h = -model.rest_volume_m3[e] * P * dm_inv.transpose();
  const Eigen::Vector3d h0 = -(h.col(0) + h.col(1) + h.col(2));
  corner_scratch.x[e] = h0.x();
  corner_scratch.y[e] = h0.y();
  corner_scratch.z[e] = h0.z();
  for (int c = 1; c < 4; ++c) {
    const std::size_t slot = c * model.tet_count + e;
    corner_scratch.x[slot] = h(0, c - 1);
    corner_scratch.y[slot] = h(1, c - 1);
    corner_scratch.z[slot] = h(2, c - 1);
  }
}

// The general element loop: laws with history (viscous) or a Mooney–Rivlin term, one loop per
// effect set, chosen once per evaluation rather than tested per element.
template <bool kFibres, bool kViscous, bool kAveragedPressure, bool kMooneyRivlin>
ElasticEvaluation element_forces(const SimModel& model, const NodeArray& position,
                                 ForceScratch& scratch, const ViscousContext& viscous,
                                 std::size_t begin, std::size_t end) {
  ElasticEvaluation seen = nothing_seen();
  for (std::size_t e = begin; e < end; ++e)
    general_element<kFibres, kViscous, kAveragedPressure, kMooneyRivlin>(model, position, scratch,
                                                                         viscous, e, seen);
  return seen;
}

// Each node sums its own corner slots, so no two writers share a node (no atomics when threaded).
void gather_corner_forces(const SimModel& model, const ForceScratch& scratch, NodeArray& force) {
  const double* cx = scratch.corner_force_n.x.data();
  const double* cy = scratch.corner_force_n.y.data();
  const double* cz = scratch.corner_force_n.z.data();
  for_each_chunk(scratch, model.node_count, kNodesPerChunk,
                 [&](std::size_t begin, std::size_t end, std::size_t) {
                   for (std::size_t n = begin; n < end; ++n) {
                     double fx = 0.0, fy = 0.0, fz = 0.0;
                     for (auto s = model.node_slot_begin[n]; s < model.node_slot_begin[n + 1];
                          ++s) {
                       const auto slot = static_cast<std::size_t>(model.node_slots[s]);
                       fx += cx[slot];
                       fy += cy[slot];
                       fz += cz[slot];
                     }
                     force.x[n] = fx;
                     force.y[n] = fy;
                     force.z[n] = fz;
                   }
                 });
}

// Folds the chunks' results in chunk order (the same numbers for any thread count).
ElasticEvaluation combine_chunks(const ForceScratch& scratch, double* dissipated_j) {
  ElasticEvaluation seen = nothing_seen();
  for (std::size_t c = 0; c < scratch.chunk_seen.size(); ++c) {
    const ElasticEvaluation& s = scratch.chunk_seen[c];
    seen.min_volume_ratio = std::min(seen.min_volume_ratio, s.min_volume_ratio);
    seen.max_volume_ratio = std::max(seen.max_volume_ratio, s.max_volume_ratio);
    seen.max_fibre_modulus_pa = std::max(seen.max_fibre_modulus_pa, s.max_fibre_modulus_pa);
    if (dissipated_j) *dissipated_j += scratch.chunk_dissipated_j[c];
  }
  return seen;
}

// The plain viscous loop takes a viscous model whose every region is viscous, committing a step.
[[maybe_unused]] bool plain_viscous_loop_applies(const SimModel& model, const EffectSet& on,
                                                 const ViscousContext& viscous) {
  if (on.mooney_rivlin || viscous.arm != nullptr) return false;
  for (const auto& parameters : model.viscous_parameters)
    if (!parameters) return false;
  return true;
}

// The plain viscous loop over every element, then the general update of those it flagged.
template <bool kFibres>
ElasticEvaluation viscous_forces(const SimModel& model, const NodeArray& position,
                                 ForceScratch& scratch, const ViscousContext& viscous,
                                 const detail::ElasticKernelData& elastic) {
  // The components the kernel reads by number (element_kernels.h).
  static_assert(ViscousHistory::kMaxwellStress == 0 && ViscousHistory::kElasticStress == 6 &&
                ViscousHistory::kInversePlasticDeformation == 12 &&
                ViscousHistory::kComponents == detail::kViscousHistoryComponents &&
                ViscousHistory::kBlock == detail::kViscousHistoryBlock &&
                kElementsPerChunk % detail::kViscousHistoryBlock == 0);
  const std::size_t regions = model.viscous_parameters.size();
  double* constants = scratch.region_constants.data();
  for (std::size_t r = 0; r < regions; ++r) {
    const ViscousTissueStep& step = *(*viscous.step_by_region)[r];
    const double mu = step.mu_instant_pa, lambda = step.lambda_instant_pa;
    const double values[10] = {
        mu,
        lambda,
        step.relaxed_fraction,
        step.arm_fraction,
        step.arm_decay,
        step.arm_loading,
        // No flow this step: nothing yields (the general update would take none).
        step.viscoplastic && step.flow_dt_s > 0.0 ? step.viscoplastic->yield_limit_pa
                                                  : std::numeric_limits<double>::infinity(),
        step.arm_fraction / (4.0 * mu),  // maxwell_arm_energy_density's factors
        lambda / (2.0 * mu + 3.0 * lambda),
        step.dt_s / step.relaxation_time_s,
    };
    for (int k = 0; k < 10; ++k) constants[k * regions + r] = values[k];
  }
  detail::ViscousKernelData data{};
  data.elastic = elastic;
  data.region = model.region.data();
  data.history = viscous.history->block(0);
  data.plastic_block = viscous.history->plastic_blocks();
  const double** fields[10] = {&data.mu_pa,
                               &data.lambda_pa,
                               &data.relaxed_fraction,
                               &data.arm_fraction,
                               &data.arm_decay,
                               &data.arm_loading,
                               &data.yield_limit_pa,
                               &data.arm_energy_scale,
                               &data.arm_energy_volumetric,
                               &data.step_over_relaxation_time};
  for (int k = 0; k < 10; ++k) *fields[k] = constants + k * regions;
  data.needs_general = scratch.needs_general.data();
  data.yield_raise_pa = model.in_vivo_stress_pa.empty() ? scratch.no_yield_raise_pa.data()
                                                        : model.in_vivo_stress_pa.data();
  const detail::ViscousKernel kernel =
      detail::elastic_kernels().viscous[kFibres ? fibre_families(elastic) : 0];
  for_each_chunk(scratch, model.tet_count, kElementsPerChunk,
                 [&](std::size_t begin, std::size_t end, std::size_t chunk) {
                   detail::ElasticKernelSeen seen = kernel_nothing_seen();
                   double& dissipated = scratch.chunk_dissipated_j[chunk];
                   dissipated = 0.0;
                   kernel(data, begin, end, seen, dissipated);
                   ElasticEvaluation general = evaluation_of(seen);
                   ViscousContext chunk_viscous = viscous;
                   chunk_viscous.dissipated_j = &dissipated;
                   for (std::size_t e = begin; e < end; ++e)
                     if (scratch.needs_general[e])
                       general_element<kFibres, true, false, false>(model, position, scratch,
                                                                    chunk_viscous, e, general);
                   scratch.chunk_seen[chunk] = general;
                 });
  return combine_chunks(scratch, viscous.dissipated_j);
}

// Picks the element loop compiled for the model's effect set and runs it over every element.
template <bool kViscous>
ElasticEvaluation element_forces_of_effects(const SimModel& model, const NodeArray& position,
                                            ForceScratch& scratch, const ViscousContext& viscous) {
  const EffectSet on = built(model);
  const detail::ElasticKernelData data = kernel_data(model, position, scratch);
  if constexpr (kViscous) {
    if (plain_viscous_loop_applies(model, on, viscous)) {
      // Every element has its own law: no averaged pressure to gather.
      if constexpr (kBuiltFibres)
        if (on.fibres) return viscous_forces<true>(model, position, scratch, viscous, data);
      return viscous_forces<false>(model, position, scratch, viscous, data);
    }
  }
  if (on.average_nodal_pressure) average_nodal_volume_ratios(model, data, scratch);
  // The vectorised loops, for models without history or a Mooney–Rivlin term (a viscous model
  // evaluated elastically keeps its viscous regions on their own pressure: the general loop).
  if (!on.viscous && !on.mooney_rivlin) {
    const detail::ElasticKernel kernel =
        detail::elastic_kernels()
            .forces[on.fibres ? fibre_families(data) : 0][on.average_nodal_pressure];
    for_each_chunk(scratch, model.tet_count, kElementsPerChunk,
                   [&](std::size_t begin, std::size_t end, std::size_t chunk) {
                     detail::ElasticKernelSeen seen = kernel_nothing_seen();
                     kernel(data, begin, end, seen);
                     scratch.chunk_seen[chunk] = evaluation_of(seen);
                   });
    return combine_chunks(scratch, nullptr);
  }
  auto run = [&](auto fibres, auto pressure, auto mooney) {
    for_each_chunk(scratch, model.tet_count, kElementsPerChunk,
                   [&](std::size_t begin, std::size_t end, std::size_t chunk) {
                     ViscousContext chunk_viscous = viscous;
                     if (viscous.dissipated_j) {
                       scratch.chunk_dissipated_j[chunk] = 0.0;
                       chunk_viscous.dissipated_j = &scratch.chunk_dissipated_j[chunk];
                     }
                     scratch.chunk_seen[chunk] =
                         element_forces<decltype(fibres)::value, kViscous,
                                        decltype(pressure)::value, decltype(mooney)::value>(
                             model, position, scratch, chunk_viscous, begin, end);
                   });
    return combine_chunks(scratch, viscous.dissipated_j);
  };
  auto with_mooney = [&](auto fibres, auto pressure) {
    if constexpr (kBuiltMooneyRivlin)
      if (on.mooney_rivlin) return run(fibres, pressure, std::true_type{});
    return run(fibres, pressure, std::false_type{});
  };
  auto with_pressure = [&](auto fibres) {
    if constexpr (kBuiltAveragedPressure)
      if (on.average_nodal_pressure) return with_mooney(fibres, std::true_type{});
    return with_mooney(fibres, std::false_type{});
  };
  if constexpr (kBuiltFibres)
    if (on.fibres) return with_pressure(std::true_type{});
  return with_pressure(std::false_type{});
}

// The same, with the smallest nodal J when it averaged the pressure over nodes.
template <bool kViscous>
ElasticEvaluation element_forces_for_effects(const SimModel& model, const NodeArray& position,
                                             ForceScratch& scratch, const ViscousContext& viscous) {
  scratch.min_nodal_volume_ratio = std::numeric_limits<double>::infinity();
  ElasticEvaluation seen = element_forces_of_effects<kViscous>(model, position, scratch, viscous);
  seen.min_nodal_volume_ratio = scratch.min_nodal_volume_ratio;
  return seen;
}

}  // namespace

double element_energy_density(const SimModel& model, std::size_t e, const Eigen::Matrix3d& F) {
  double psi = neo_hookean::energy_density(F, model.shear_modulus_pa[e], model.lame_lambda_pa[e]);
  if (built(model).mooney_rivlin)
    psi += mooney_rivlin::extra_energy_density(F, model.mooney_rivlin_c2_pa[e]);
  if (built(model).fibres)
    for (const auto& family : model.fibre_direction)
      psi += hgo::energy_density(F, family[e], model.fibre_parameters[e]);
  return psi;
}

Eigen::Matrix3d element_first_piola_stress(const SimModel& model, std::size_t e,
                                           const Eigen::Matrix3d& F) {
  ElasticEvaluation ignored;
  const double J = F.determinant();  // a single element: its own J is the average
  Eigen::Matrix3d P = built(model).fibres
                          ? stress_of<true, false, false, false>(model, e, F, J, ignored, {})
                          : stress_of<false, false, false, false>(model, e, F, J, ignored, {});
  if (built(model).mooney_rivlin)
    P += mooney_rivlin::extra_first_piola_stress(F, model.mooney_rivlin_c2_pa[e]);
  return P;
}

Eigen::Matrix<double, 9, 9> element_stress_tangent(const SimModel& model, std::size_t e,
                                                   const Eigen::Matrix3d& F) {
  Eigen::Matrix<double, 9, 9> tangent =
      neo_hookean::stress_tangent(F, model.shear_modulus_pa[e], model.lame_lambda_pa[e]);
  if (built(model).mooney_rivlin)
    tangent += mooney_rivlin::extra_stress_tangent(F, model.mooney_rivlin_c2_pa[e]);
  if (built(model).fibres)
    for (const auto& family : model.fibre_direction)
      tangent += hgo::stress_tangent(F, family[e], model.fibre_parameters[e]);
  return tangent;
}

#ifndef LIVERSIM_FORCES_VARIANT
std::string_view element_kernel_instruction_set() {
  return detail::elastic_kernels().instruction_set;
}
#endif

ElasticEvaluation compute_elastic_forces(const SimModel& model, const NodeArray& position,
                                         ForceScratch& scratch, NodeArray& force) {
  require_built(model);
  const ElasticEvaluation seen = element_forces_for_effects<false>(model, position, scratch, {});
  gather_corner_forces(model, scratch, force);
  return seen;
}

ElasticEvaluation compute_internal_forces(const SimModel& model, SimState& state,
                                          double dt_since_last_s) {
  require_built(model);
  if constexpr (kBuiltViscous) {
    if (model.effects.viscous) {
      // The flow is due once the interval has passed; then it covers all the time since the last.
      double flow_dt_s = dt_since_last_s;
      if (model.plastic_flow_interval_s > 0.0) {
        double& pending = state.viscous_history.flow_pending_s;
        pending += dt_since_last_s;
        const bool due = pending >= model.plastic_flow_interval_s * (1.0 - 1e-9);
        flow_dt_s = due ? pending : 0.0;
        if (due) pending = 0.0;
      }
      for (std::size_t r = 0; r < model.viscous_parameters.size(); ++r)
        if (model.viscous_parameters[r]) {
          state.viscous_step[r].emplace(*model.viscous_parameters[r], dt_since_last_s);
          state.viscous_step[r]->flow_dt_s = flow_dt_s;
        }
      ElasticEvaluation seen =
          element_forces_for_effects<true>(model, state.position_m, state.force_scratch,
                                           {&state.viscous_history, &state.viscous_step, nullptr,
                                            &state.energy.viscous_dissipated_j});
      gather_corner_forces(model, state.force_scratch, state.force_n);
      seen.max_flow_stiffening = state.viscous_history.largest_flow_stiffening();
      return seen;
    }
  }
  return here::compute_elastic_forces(model, state.position_m, state.force_scratch, state.force_n);
}

ElasticEvaluation compute_internal_forces_rate_form(const SimModel& model, SimState& state,
                                                    const NodeArray& position,
                                                    const ViscousArmInputs& arm, NodeArray& force) {
  require_built(model);
  if constexpr (kBuiltViscous) {
    if (model.effects.viscous) {
      // The rate form needs only the step's moduli, not its length.
      for (std::size_t r = 0; r < model.viscous_parameters.size(); ++r)
        if (model.viscous_parameters[r] && !state.viscous_step[r])
          state.viscous_step[r].emplace(*model.viscous_parameters[r], 0.0);
      ElasticEvaluation seen =
          element_forces_for_effects<true>(model, position, state.force_scratch,
                                           {&state.viscous_history, &state.viscous_step, &arm});
      gather_corner_forces(model, state.force_scratch, force);
      seen.max_flow_stiffening = state.viscous_history.largest_flow_stiffening();
      return seen;
    }
  }
  return here::compute_elastic_forces(model, position, state.force_scratch, force);
}

Eigen::Matrix<double, 9, 9> element_step_tangent(const SimModel& model, const SimState& state,
                                                 const ViscousArmInputs& arm, std::size_t e,
                                                 const Eigen::Matrix3d& F) {
  const auto r = static_cast<std::size_t>(model.region[e]);
  if (built(model).viscous && model.viscous_parameters[r] && state.viscous_step[r]) {
    Eigen::Matrix<double, 9, 9> tangent = viscoelastic_stress_tangent_rate_form(
        F, *state.viscous_step[r], state.viscous_history.inverse_plastic_deformation(e),
        arm.q_known[e], arm.keep_by_region[r], arm.elastic_weight_by_region[r]);
    if (built(model).fibres)
      for (const auto& family : model.fibre_direction)
        tangent += hgo::stress_tangent(F, family[e], model.fibre_parameters[e]);
    return tangent;
  }
  return here::element_stress_tangent(model, e, F);
}

double critical_damping_n_s_per_m(double stiffness_n_per_m, double mass_kg) {
  return 2.0 * std::sqrt(stiffness_n_per_m * mass_kg);
}

Eigen::Vector3d spring_reaction_force_n(std::span<const NodeSpring> springs,
                                        const NodeArray& position) {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  for (const NodeSpring& s : springs)
    force += s.stiffness_n_per_m * (position.at(s.node) - s.anchor_m);
  return force;
}

void add_external_forces(const StepInputs& inputs, const NodeArray& position, NodeArray& force) {
  for (const auto& load : inputs.point_loads) {
    force.x[load.node] += load.force_n.x();
    force.y[load.node] += load.force_n.y();
    force.z[load.node] += load.force_n.z();
  }
  for (const auto& spring : inputs.springs) {
    const auto n = spring.node;
    force.x[n] += spring.stiffness_n_per_m * (spring.anchor_m.x() - position.x[n]);
    force.y[n] += spring.stiffness_n_per_m * (spring.anchor_m.y() - position.y[n]);
    force.z[n] += spring.stiffness_n_per_m * (spring.anchor_m.z() - position.z[n]);
  }
}

void add_gravity_forces(const SimModel& model, NodeArray& force) {
  if constexpr (!kBuiltGravity) return;
  if (!model.effects.gravity) return;
  const Eigen::Vector3d g = model.gravity_m_per_s2;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    const double mass = model.lumped_mass_kg[n];
    force.x[n] += mass * g.x();
    force.y[n] += mass * g.y();
    force.z[n] += mass * g.z();
  }
}

double support_damping_per_s(const SimModel& model) {
  if constexpr (!kBuiltGravity) return 0.0;
  if (!model.support) return 0.0;
  return 2.0 * model.support_damping_ratio * std::sqrt(model.support_stiffness_per_kg);
}

void add_support_forces(const SimModel& model, const NodeArray& position, NodeArray& force,
                        const SupportDamping& damping) {
  if constexpr (!kBuiltGravity) return;
  if (!model.support) return;
  const SupportSurface& support = *model.support;
  const double rate = here::support_damping_per_s(model);
  for (std::size_t n = 0; n < model.node_count; ++n) {
    if (model.is_fixed[n]) continue;
    const SupportContact contact =
        support_contact(support, position.at(n), model.rest_position_m.at(n),
                        model.lumped_mass_kg[n] * model.support_stiffness_per_kg,
                        model.support_friction_coefficient);
    if (!contact.touching) continue;
    Eigen::Vector3d f = contact.force_n;
    if (damping.rate_per_s)
      (*damping.rate_per_s)[n] += rate;
    else if (damping.velocity)
      f -= rate * model.lumped_mass_kg[n] * damping.velocity->at(n);
    force.x[n] += f.x();
    force.y[n] += f.y();
    force.z[n] += f.z();
  }
}

ElasticEvaluation compute_tissue_forces(const SimModel& model, SimState& state,
                                        double dt_since_last_s) {
  const ElasticEvaluation seen = here::compute_internal_forces(model, state, dt_since_last_s);
  here::add_gravity_forces(model, state.force_n);
  here::add_support_forces(model, state.position_m, state.force_n, {});
  return seen;
}

double strain_energy_j(const SimModel& model, const NodeArray& position) {
  double energy = 0.0;
  for (std::size_t e = 0; e < model.tet_count; ++e)
    energy +=
        model.rest_volume_m3[e] *
        here::element_energy_density(model, e, here::deformation_gradient(model, position, e));
  return energy;
}

double kinetic_energy_j(const SimModel& model, const NodeArray& velocity) {
  double energy = 0.0;
  for (std::size_t n = 0; n < model.node_count; ++n) {
    energy += 0.5 * model.lumped_mass_kg[n] *
              (velocity.x[n] * velocity.x[n] + velocity.y[n] * velocity.y[n] +
               velocity.z[n] * velocity.z[n]);
  }
  return energy;
}

}  // namespace LIVERSIM_FORCES_NAMESPACE
