// The element kernels' source, included once per instruction set by element_kernels_*.cpp with
// LIVERSIM_KERNEL_ISA naming the namespace. Everything here has internal linkage and uses no
// library code but compiler builtins, so code built for AVX2 cannot be linked into the other.
// The laws are those of material.cpp and fibres.cpp, written out per entry; test_kernels checks
// the results against them.
#include "element_kernels.h"

#ifndef LIVERSIM_KERNEL_ISA
#error "define LIVERSIM_KERNEL_ISA before including element_kernels_body.h"
#endif

namespace liversim::detail::LIVERSIM_KERNEL_ISA {
namespace {

// neo_hookean::kMinVolumeRatio, fibres' kMaxExponent (material.h, fibres.h; test_kernels
// compares the laws on both sides of each).
constexpr double kMinVolumeRatio = 0.2;
constexpr double kLogMinVolumeRatio = -1.6094379124341003;  // ln 0.2
constexpr double kMaxExponent = 50.0;
constexpr double kLn2Hi = 6.93147180369123816490e-01, kLn2Lo = 1.90821492927058770002e-10;

inline std::uint64_t bits_of(double x) {
  std::uint64_t b;
  __builtin_memcpy(&b, &x, sizeof b);
  return b;
}
inline double double_of(std::uint64_t b) {
  double x;
  __builtin_memcpy(&x, &b, sizeof x);
  return x;
}
inline double min_of(double a, double b) {
  return a < b ? a : b;
}
inline double max_of(double a, double b) {
  return a > b ? a : b;
}

// ln x for finite x > 0 (normal), to about one ulp, without branches so that it vectorises:
// x = 2ᵏ·m with m in [√½, √2), ln m = 2 atanh s with s = (m − 1)/(m + 1), |s| < 0.172, by its
// series to s²¹ (the next term is below 2e−17 of the sum).
inline double log_of(double x) {
  const std::uint64_t b = bits_of(x);
  // The exponent as a double: its 11 bits put in the mantissa of 2⁵² and 2⁵² taken off.
  double k = double_of(((b >> 52) & 0x7ff) | 0x4330000000000000ull) - 4503599627370496.0 - 1023.0;
  double m = double_of((b & 0x000fffffffffffffull) | 0x3ff0000000000000ull);
  const bool high = m > 1.4142135623730951;
  m = high ? 0.5 * m : m;
  k = high ? k + 1.0 : k;
  const double s = (m - 1.0) / (m + 1.0), s2 = s * s;
  double series = 1.0 / 21.0;
  series = series * s2 + 1.0 / 19.0;
  series = series * s2 + 1.0 / 17.0;
  series = series * s2 + 1.0 / 15.0;
  series = series * s2 + 1.0 / 13.0;
  series = series * s2 + 1.0 / 11.0;
  series = series * s2 + 1.0 / 9.0;
  series = series * s2 + 1.0 / 7.0;
  series = series * s2 + 1.0 / 5.0;
  series = series * s2 + 1.0 / 3.0;
  const double log_m = 2.0 * s + 2.0 * s * s2 * series;
  return k * kLn2Hi + (log_m + k * kLn2Lo);
}

// eˣ for x in [0, kMaxExponent], to about one ulp, without branches: x = k·ln 2 + r, |r| ≤ ½ ln 2,
// eʳ by its Taylor series to r¹³ (the next term is below 5e−18).
inline double exp_of(double x) {
  constexpr double kRound = 6755399441055744.0;  // 1.5·2⁵²: adding it rounds to an integer
  const double shifted = x * 1.4426950408889634 + kRound;
  const double k = shifted - kRound;
  const double r = (x - k * kLn2Hi) - k * kLn2Lo;
  double series = 1.0 / 6227020800.0;  // 1/13!
  series = series * r + 1.0 / 479001600.0;
  series = series * r + 1.0 / 39916800.0;
  series = series * r + 1.0 / 3628800.0;
  series = series * r + 1.0 / 362880.0;
  series = series * r + 1.0 / 40320.0;
  series = series * r + 1.0 / 5040.0;
  series = series * r + 1.0 / 720.0;
  series = series * r + 1.0 / 120.0;
  series = series * r + 1.0 / 24.0;
  series = series * r + 1.0 / 6.0;
  series = series * r + 0.5;
  series = series * r + 1.0;
  series = series * r + 1.0;
  // 2ᵏ from k's bits in the low mantissa of `shifted` (0 ≤ k ≤ 73).
  const double two_k = double_of(((bits_of(shifted) & 0x7ff) + 1023) << 52);
  return series * two_k;
}

struct Matrix3 {
  double m[3][3];
};

inline Matrix3 deformation_gradient(const ElasticKernelData& d, std::size_t e) {
  const std::int32_t n0 = d.corner[0][e], n1 = d.corner[1][e], n2 = d.corner[2][e],
                     n3 = d.corner[3][e];
  const double x0 = d.x[n0], y0 = d.y[n0], z0 = d.z[n0];
  // Ds = [x1 − x0, x2 − x0, x3 − x0] by rows of coordinates.
  const double ds[3][3] = {{d.x[n1] - x0, d.x[n2] - x0, d.x[n3] - x0},
                           {d.y[n1] - y0, d.y[n2] - y0, d.y[n3] - y0},
                           {d.z[n1] - z0, d.z[n2] - z0, d.z[n3] - z0}};
  Matrix3 F;
#pragma GCC unroll 3
  for (int i = 0; i < 3; ++i)
#pragma GCC unroll 3
    for (int k = 0; k < 3; ++k)
      F.m[i][k] = ds[i][0] * d.dm_inverse[k][e] + ds[i][1] * d.dm_inverse[3 + k][e] +
                  ds[i][2] * d.dm_inverse[6 + k][e];
  return F;
}

// cof F: column j is the cross product of the other two columns of F.
inline Matrix3 cofactor(const Matrix3& f) {
  const auto& F = f.m;
  Matrix3 c;
  c.m[0][0] = F[1][1] * F[2][2] - F[2][1] * F[1][2];
  c.m[1][0] = F[2][1] * F[0][2] - F[0][1] * F[2][2];
  c.m[2][0] = F[0][1] * F[1][2] - F[1][1] * F[0][2];
  c.m[0][1] = F[1][2] * F[2][0] - F[2][2] * F[1][0];
  c.m[1][1] = F[2][2] * F[0][0] - F[0][2] * F[2][0];
  c.m[2][1] = F[0][2] * F[1][0] - F[1][2] * F[0][0];
  c.m[0][2] = F[1][0] * F[2][1] - F[2][0] * F[1][1];
  c.m[1][2] = F[2][0] * F[0][1] - F[0][0] * F[2][1];
  c.m[2][2] = F[0][0] * F[1][1] - F[1][0] * F[0][1];
  return c;
}

// hgo::first_piola_stress of each family added to P; returns the largest
// hgo::tangent_modulus_pa (2ψ4 + 4 I4 ψ44) among them.
template <int kFibreFamilies>
inline double add_fibre_stress(const ElasticKernelData& d, std::size_t e, const Matrix3& F,
                               double (&P)[3][3]) {
  const double k1 = d.fibre_parameters[2 * e], k2 = d.fibre_parameters[2 * e + 1];
  double max_modulus = 0.0;
#pragma GCC unroll 3
  for (int f = 0; f < kFibreFamilies; ++f) {
    const double a[3] = {d.fibre_direction[f][3 * e], d.fibre_direction[f][3 * e + 1],
                         d.fibre_direction[f][3 * e + 2]};
    double fa[3];
#pragma GCC unroll 3
    for (int i = 0; i < 3; ++i) fa[i] = F.m[i][0] * a[0] + F.m[i][1] * a[1] + F.m[i][2] * a[2];
    const double i4 = fa[0] * fa[0] + fa[1] * fa[1] + fa[2] * fa[2];
    const double stretch = i4 - 1.0;
    const bool active = stretch > 0.0 && k1 != 0.0;
    // 2ψ4·(Fa)⊗a with ψ4 = k1 (I4 − 1) e^{min(k2 (I4−1)², 50)}.
    const double x = k2 * stretch * stretch;
    const double exponential = exp_of(min_of(active ? x : 0.0, kMaxExponent));
    const double psi4 = active ? k1 * stretch * exponential : 0.0;
#pragma GCC unroll 3
    for (int i = 0; i < 3; ++i)
#pragma GCC unroll 3
      for (int k = 0; k < 3; ++k) P[i][k] += 2.0 * psi4 * fa[i] * a[k];
    const double psi44 = k1 * exponential * (1.0 + (x <= kMaxExponent ? 2.0 * x : 0.0));
    max_modulus = max_of(max_modulus, active ? 2.0 * psi4 + 4.0 * i4 * psi44 : 0.0);
  }
  return max_modulus;
}

// Corners 1..3 get the columns of −V·P·Dm⁻ᵀ; corner 0 balances them.
inline void store_corner_forces(const ElasticKernelData& d, std::size_t e,
                                const double (&P)[3][3]) {
  const double v = d.rest_volume_m3[e];
  double h0[3] = {0.0, 0.0, 0.0};
#pragma GCC unroll 3
  for (int c = 0; c < 3; ++c) {
#pragma GCC unroll 3
    for (int i = 0; i < 3; ++i) {
      const double h =
          -v * (P[i][0] * d.dm_inverse[3 * c][e] + P[i][1] * d.dm_inverse[3 * c + 1][e] +
                P[i][2] * d.dm_inverse[3 * c + 2][e]);
      d.corner_force[c + 1][i][e] = h;
      h0[i] -= h;
    }
  }
#pragma GCC unroll 3
  for (int i = 0; i < 3; ++i) d.corner_force[0][i][e] = h0[i];
}

template <int kFibreFamilies, bool kAveragedPressure>
void element_forces(const ElasticKernelData& data, std::size_t begin, std::size_t end,
                    ElasticKernelSeen& seen) {
  const ElasticKernelData d = data;  // a local copy: its pointers stay in registers
  double min_j = seen.min_volume_ratio, max_j = seen.max_volume_ratio;
  double max_fibre = seen.max_fibre_modulus_pa;
#pragma omp simd reduction(min : min_j) reduction(max : max_j, max_fibre)
  for (std::size_t e = begin; e < end; ++e) {
    const Matrix3 F = deformation_gradient(d, e);
    const Matrix3 cof = cofactor(F);
    const double J = F.m[0][0] * cof.m[0][0] + F.m[1][0] * cof.m[1][0] + F.m[2][0] * cof.m[2][0];
    min_j = min_of(min_j, J);
    max_j = max_of(max_j, J);
    const double mu = d.shear_modulus_pa[e], lambda = d.lame_lambda_pa[e];
    const bool compressed = !(J >= kMinVolumeRatio);
    // P = μF + p·cof F with p = U'(J) (material.cpp), U continued quadratically below J0.
    double pressure_term;
    if constexpr (kAveragedPressure) {
      // U'(J) − p_λ(J) + p_λ̄: the λ parts cancel to −μ/J (or its continuation).
      const double averaged =
          0.25 *
          (d.nodal_lambda_pressure_pa[d.corner[0][e]] + d.nodal_lambda_pressure_pa[d.corner[1][e]] +
           d.nodal_lambda_pressure_pa[d.corner[2][e]] + d.nodal_lambda_pressure_pa[d.corner[3][e]]);
      const double own = compressed
                             ? -mu / kMinVolumeRatio +
                                   mu / (kMinVolumeRatio * kMinVolumeRatio) * (J - kMinVolumeRatio)
                             : -mu / J;
      pressure_term = own + averaged;
    } else {
      const double slope = (lambda * kLogMinVolumeRatio - mu) / kMinVolumeRatio;
      const double curvature =
          (lambda * (1.0 - kLogMinVolumeRatio) + mu) / (kMinVolumeRatio * kMinVolumeRatio);
      const double log_j = log_of(compressed ? 1.0 : J);
      pressure_term =
          compressed ? slope + curvature * (J - kMinVolumeRatio) : (lambda * log_j - mu) / J;
    }
    double P[3][3];
#pragma GCC unroll 3
    for (int i = 0; i < 3; ++i)
#pragma GCC unroll 3
      for (int k = 0; k < 3; ++k) P[i][k] = mu * F.m[i][k] + pressure_term * cof.m[i][k];
    if constexpr (kFibreFamilies > 0)
      max_fibre = max_of(max_fibre, add_fibre_stress<kFibreFamilies>(d, e, F, P));
    store_corner_forces(d, e, P);
  }
  seen.min_volume_ratio = min_j;
  seen.max_volume_ratio = max_j;
  seen.max_fibre_modulus_pa = max_fibre;
}

void volume_ratios(const ElasticKernelData& data, std::size_t begin, std::size_t end) {
  const ElasticKernelData d = data;
#pragma omp simd
  for (std::size_t e = begin; e < end; ++e) {
    const Matrix3 F = deformation_gradient(d, e);
    const Matrix3 cof = cofactor(F);
    d.volume_ratio[e] = F.m[0][0] * cof.m[0][0] + F.m[1][0] * cof.m[1][0] + F.m[2][0] * cof.m[2][0];
  }
}

// viscous_tissue_stress (viscous_tissue.cpp) without its two rare branches: an element that
// yields or has collapsed is flagged, keeps its history untouched here, and is updated by the
// general code afterwards.
template <int kFibreFamilies>
void viscous_forces(const ViscousKernelData& data, std::size_t begin, std::size_t end,
                    ElasticKernelSeen& seen, double& dissipated_j) {
  const ViscousKernelData v = data;
  const ElasticKernelData d = data.elastic;
  double min_j = seen.min_volume_ratio, max_j = seen.max_volume_ratio;
  double max_fibre = seen.max_fibre_modulus_pa, dissipated = 0.0;
#pragma omp simd reduction(min : min_j) reduction(max : max_j, max_fibre) reduction(+ : dissipated)
  for (std::size_t e = begin; e < end; ++e) {
    const Matrix3 F = deformation_gradient(d, e);
    double* history = v.state + e * kViscousStateDoubles;
    const std::int32_t r = v.region[e];
    const double mu = v.mu_pa[r], lambda = v.lambda_pa[r];
    // Fe = F·Fp⁻¹ (Fp⁻¹ stored column-major).
    Matrix3 fe;
#pragma GCC unroll 3
    for (int i = 0; i < 3; ++i)
#pragma GCC unroll 3
      for (int k = 0; k < 3; ++k)
        fe.m[i][k] = F.m[i][0] * history[12 + 3 * k] + F.m[i][1] * history[13 + 3 * k] +
                     F.m[i][2] * history[14 + 3 * k];
    const Matrix3 cof = cofactor(fe);
    const double J = fe.m[0][0] * cof.m[0][0] + fe.m[1][0] * cof.m[1][0] + fe.m[2][0] * cof.m[2][0];
    min_j = min_of(min_j, J);
    max_j = max_of(max_j, J);
    const bool collapsed = !(J >= kMinVolumeRatio);
    const double safe_j = collapsed ? 1.0 : J;
    // S_e = Fe⁻¹·P(Fe) = μI + U'(J)/J·cofᵀ·cof, with U'(J) = (λ ln J − μ)/J.
    const double volumetric = (lambda * log_of(safe_j) - mu) / (safe_j * safe_j);
    // (cofᵀ·cof)_ab = column a of cof · column b of cof. Voigt: xx, yy, zz, yz, xz, xy.
    auto cc = [&](int a, int b) {
      return cof.m[0][a] * cof.m[0][b] + cof.m[1][a] * cof.m[1][b] + cof.m[2][a] * cof.m[2][b];
    };
    const double elastic[6] = {mu + volumetric * cc(0, 0), mu + volumetric * cc(1, 1),
                               mu + volumetric * cc(2, 2), volumetric * cc(1, 2),
                               volumetric * cc(0, 2),      volumetric * cc(0, 1)};
    // H = g·H_before + h·(S_e − S_e before); S = g0·S_e + g1·H.
    const double decay = v.arm_decay[r], loading = v.arm_loading[r];
    const double g0 = v.relaxed_fraction[r], g1 = v.arm_fraction[r];
    double arm[6], pk2[6];
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {
      arm[k] = decay * history[k] + loading * (elastic[k] - history[6 + k]);
      pk2[k] = g0 * elastic[k] + g1 * arm[k];
    }
    const double S[3][3] = {
        {pk2[0], pk2[5], pk2[4]}, {pk2[5], pk2[1], pk2[3]}, {pk2[4], pk2[3], pk2[2]}};
    // Fe·S, then the Kirchhoff stress τ = Fe·S·Feᵀ for the yield check.
    double feS[3][3];
#pragma GCC unroll 3
    for (int i = 0; i < 3; ++i)
#pragma GCC unroll 3
      for (int k = 0; k < 3; ++k)
        feS[i][k] = fe.m[i][0] * S[0][k] + fe.m[i][1] * S[1][k] + fe.m[i][2] * S[2][k];
    double tau[3][3];
#pragma GCC unroll 3
    for (int i = 0; i < 3; ++i)
#pragma GCC unroll 3
      for (int k = 0; k < 3; ++k)
        tau[i][k] = feS[i][0] * fe.m[k][0] + feS[i][1] * fe.m[k][1] + feS[i][2] * fe.m[k][2];
    const double mean = (tau[0][0] + tau[1][1] + tau[2][2]) / 3.0;
    double deviator_sq = 0.0;
#pragma GCC unroll 3
    for (int i = 0; i < 3; ++i)
#pragma GCC unroll 3
      for (int k = 0; k < 3; ++k) {
        const double symmetric = 0.5 * (tau[i][k] + tau[k][i]) - (i == k ? mean : 0.0);
        deviator_sq += symmetric * symmetric;
      }
    const bool yields = 1.5 * deviator_sq > v.yield_limit_pa[r] * v.yield_limit_pa[r];
    const bool general = collapsed || yields;
    v.needs_general[e] = general ? 1 : 0;
    // P = Fe·S·Fp⁻ᵀ: (Fp⁻ᵀ)[k][j] = Fp⁻¹[j][k], stored at 12 + j + 3k.
    double P[3][3];
#pragma GCC unroll 3
    for (int i = 0; i < 3; ++i)
#pragma GCC unroll 3
      for (int j = 0; j < 3; ++j)
        P[i][j] =
            feS[i][0] * history[12 + j] + feS[i][1] * history[15 + j] + feS[i][2] * history[18 + j];
    if constexpr (kFibreFamilies > 0)
      max_fibre = max_of(max_fibre, add_fibre_stress<kFibreFamilies>(d, e, F, P));
    store_corner_forces(d, e, P);
    // The dashpots' work over the step: V·Δt/τ·(ψ(H before) + ψ(H)) (trapezoid of 2ψ/τ).
    const double trace_before = history[0] + history[1] + history[2];
    const double trace_after = arm[0] + arm[1] + arm[2];
    double contraction_before = 0.0, contraction_after = 0.0;
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {
      const double weight = k < 3 ? 1.0 : 2.0;
      contraction_before += weight * history[k] * history[k];
      contraction_after += weight * arm[k] * arm[k];
    }
    const double b_vol = v.arm_energy_volumetric[r];
    const double work = d.rest_volume_m3[e] * v.step_over_relaxation_time[r] *
                        v.arm_energy_scale[r] *
                        (contraction_before - b_vol * trace_before * trace_before +
                         contraction_after - b_vol * trace_after * trace_after);
    dissipated += general ? 0.0 : work;
    // Commit; a flagged element keeps what it had for the general update.
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {
      history[k] = general ? history[k] : arm[k];
      history[6 + k] = general ? history[6 + k] : elastic[k];
    }
  }
  seen.min_volume_ratio = min_j;
  seen.max_volume_ratio = max_j;
  seen.max_fibre_modulus_pa = max_fibre;
  dissipated_j += dissipated;
}

double multiply_add_chains(long iterations) {
  // 40 chains: ten 4-wide registers in flight, more than the multiply-add latency needs.
  double chain[40];
  for (int k = 0; k < 40; ++k) chain[k] = 0.01 * k;
  for (long i = 0; i < iterations; ++i) {
#pragma omp simd
    for (int k = 0; k < 40; ++k) chain[k] = chain[k] * 0.999999 + 1e-7;
  }
  double sum = 0.0;
  for (int k = 0; k < 40; ++k) sum += chain[k];
  return sum;
}

}  // namespace

const ElasticKernels& elastic_kernels() {
  static const ElasticKernels kernels{{{element_forces<0, false>, element_forces<0, true>},
                                       {element_forces<1, false>, element_forces<1, true>},
                                       {element_forces<2, false>, element_forces<2, true>}},
                                      {viscous_forces<0>, viscous_forces<1>, viscous_forces<2>},
                                      volume_ratios,
                                      multiply_add_chains,
                                      LIVERSIM_KERNEL_ISA_NAME};
  return kernels;
}

}  // namespace liversim::detail::LIVERSIM_KERNEL_ISA
