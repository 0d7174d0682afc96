#pragma once
// The vectorised element kernels: Neo-Hookean, with or without average nodal pressure, with or
// without HGO fibres, and the viscous tissue law of models whose regions are all viscous. Their
// loops run over elements in structure
// of arrays so the compiler puts several elements in one vector register; they are compiled twice
// (element_kernels_generic.cpp for any x86-64, element_kernels_avx2.cpp with AVX2 + FMA) and the
// build for the running processor is picked once. This header is all the two translation units
// share: plain pointers, no inline library code whose instruction set could leak between them.

#include <cstddef>
#include <cstdint>

namespace liversim::detail {

// Views of the model, state and scratch arrays one element loop reads and writes.
struct ElasticKernelData {
  const std::int32_t* corner[4];
  const double* x;
  const double* y;
  const double* z;
  const double* dm_inverse[9];  // row-major Dm⁻¹ entries per element
  const double* rest_volume_m3;
  const double* shear_modulus_pa;
  const double* lame_lambda_pa;
  const double* nodal_lambda_pressure_pa;  // average nodal pressure: p_λ̄(J̄) per node
  // Fibres: k1, k2 of element e at fibre_parameters[2e], [2e + 1]; the unit direction of family f
  // at fibre_direction[f][3e..3e+2] (zero where the element has none), the families present first.
  const double* fibre_parameters;
  const double* fibre_direction[2];
  double* corner_force[4][3];  // out: the nodal force of each corner, before the gather
  double* volume_ratio;        // out (volume-ratio loop): J per element
};

struct ElasticKernelSeen {
  double min_volume_ratio, max_volume_ratio, max_fibre_modulus_pa;
};

// The viscous tissue law (viscous_tissue.cpp) of elements whose regions all have one: the
// elements' history in blocks of kViscousHistoryBlock (ViscousHistory: component k of element e at
// history[(e / block · components + k) · block + e % block]; Voigt H in components [0, 6), S_e
// in [6, 12), Fp⁻¹ column-major in [12, 21), the flow's stiffening in 23), the step's constants per
// region. The loops run a block at a time (element ranges start at a block's first element).
inline constexpr std::size_t kViscousHistoryBlock = 64;
inline constexpr std::size_t kViscousHistoryComponents = 24;
struct ViscousKernelData {
  ElasticKernelData elastic;  // geometry, fibres, outputs (its moduli arrays are not read)
  const std::int32_t* region;
  double* history;
  // Per region: instantaneous μ and λ; g0, g1; arm decay g and loading h; yield limit (∞: none);
  // the arm's stored energy ψ = a·(H:H − b·(tr H)²) with a = g1/(4μ), b = λ/(2μ + 3λ); Δt/τ.
  const double* mu_pa;
  const double* lambda_pa;
  const double* relaxed_fraction;
  const double* arm_fraction;
  const double* arm_decay;
  const double* arm_loading;
  const double* yield_limit_pa;
  const double* arm_energy_scale;
  const double* arm_energy_volumetric;
  const double* step_over_relaxation_time;
  // Per element: what its yield limit is raised by (SimModel::in_vivo_stress_pa; zeros: nothing).
  const double* yield_raise_pa;
  // Per block: 0 where every element of it has Fp = I (ViscousHistory::plastic_blocks).
  const std::uint8_t* plastic_block;
  // Out: 1 where the element yields or has collapsed (J < J0): its history is left untouched and
  // its forces to the general update (viscous_tissue_update), which handles both.
  std::uint8_t* needs_general;
};

// Forces of elements [begin, end); folds what they saw into `seen`.
using ElasticKernel = void (*)(const ElasticKernelData&, std::size_t begin, std::size_t end,
                               ElasticKernelSeen& seen);
// J = det F of elements [begin, end) into data.volume_ratio.
using VolumeRatioKernel = void (*)(const ElasticKernelData&, std::size_t begin, std::size_t end);

// Forces of viscous elements [begin, end) and the commit of their history; adds the dashpots' work
// of the step (J) to `dissipated_j`.
using ViscousKernel = void (*)(const ViscousKernelData&, std::size_t begin, std::size_t end,
                               ElasticKernelSeen& seen, double& dissipated_j);

struct ElasticKernels {
  ElasticKernel forces[3][2];  // [fibre families][average nodal pressure]
  ViscousKernel viscous[3];    // [fibre families]
  VolumeRatioKernel volume_ratio;
  // Independent multiply-add chains, bound by floating-point throughput alone: the benchmark's
  // measure of what several threads can gain on this machine (performance.h).
  double (*multiply_add_chains)(long iterations);
  const char* instruction_set;
};

namespace generic {
const ElasticKernels& elastic_kernels();
}
namespace avx2 {
const ElasticKernels& elastic_kernels();
}

// The build for this processor (AVX2 + FMA when it has them), chosen on first use.
const ElasticKernels& elastic_kernels();

}  // namespace liversim::detail
