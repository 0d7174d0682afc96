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

// J = det F = det Ds / det Dm, det Dm = 6 V: the deformed volume over the rest volume, without
// forming F (half the arithmetic of the loop that does).
void volume_ratios(const ElasticKernelData& data, std::size_t begin, std::size_t end) {
  const ElasticKernelData d = data;
#pragma omp simd
  for (std::size_t e = begin; e < end; ++e) {
    const std::int32_t n0 = d.corner[0][e], n1 = d.corner[1][e], n2 = d.corner[2][e],
                       n3 = d.corner[3][e];
    const double x0 = d.x[n0], y0 = d.y[n0], z0 = d.z[n0];
    const double ax = d.x[n1] - x0, ay = d.y[n1] - y0, az = d.z[n1] - z0;
    const double bx = d.x[n2] - x0, by = d.y[n2] - y0, bz = d.z[n2] - z0;
    const double cx = d.x[n3] - x0, cy = d.y[n3] - y0, cz = d.z[n3] - z0;
    const double six_volume =
        ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx);
    d.volume_ratio[e] = six_volume / (6.0 * d.rest_volume_m3[e]);
  }
}

// The viscous elements run in blocks of kViscousBlock, each block in stages (deformation, elastic
// deformation, elastic stress and arm, stress and commit, fibres, corner forces) whose loops pass
// their results through arrays on the stack: one loop over the whole law holds more values than
// there are vector registers, and spilling them cost more than the stages' loads (measured).
constexpr std::size_t kViscousBlock = kViscousHistoryBlock;

struct ViscousBlock {
  alignas(32) double deformation[9][kViscousBlock];          // F, row-major entries
  alignas(32) double elastic_deformation[9][kViscousBlock];  // Fe = F·Fp⁻¹
  alignas(32) double elastic_stress[6][kViscousBlock];       // S_e(Fe), Voigt
  alignas(32) double arm[6][kViscousBlock];                  // H after the step, Voigt
  alignas(32) double stress[9][kViscousBlock];               // P, row-major entries
  // 1: left to the general update. needs_general holds the same as bytes; the commit loop reading
  // those ran 12-15 % slower (measured), so the loop after the yield check gets a double of its
  // own.
  alignas(32) double flagged[kViscousBlock];
  alignas(32) double dashpot_work_j[kViscousBlock];  // 0 where flagged
};

inline Matrix3 load_matrix(const double (&m)[9][kViscousBlock], std::size_t i) {
  Matrix3 a;
#pragma GCC unroll 9
  for (int k = 0; k < 9; ++k) a.m[k / 3][k % 3] = m[k][i];
  return a;
}

// The law of elements [block, block + count): viscous_tissue_stress (viscous_tissue.cpp) without
// its two rare branches. An element that yields or has collapsed is flagged, keeps its history
// untouched here, and is updated by the general code afterwards. kUniform: every element of the
// block is in the region `uniform_region` (its constants are then loaded once). kPlastic: an
// element of the block has Fp ≠ I; without, Fe = F and the products with Fp⁻¹ are skipped.
template <bool kUniform, bool kPlastic>
void viscous_law(const ViscousKernelData& data, std::size_t block, std::size_t count,
                 std::int32_t uniform_region, ViscousBlock& b, double& min_j_out, double& max_j_out,
                 double& dissipated_out) {
  const ViscousKernelData v = data;
  const double* rest_volume = data.elastic.rest_volume_m3;
  // Component k of element block + i at history[k·kViscousBlock + i].
  double* const history =
      v.history + block / kViscousBlock * kViscousHistoryComponents * kViscousBlock;
  const std::int32_t ru = uniform_region;
  // A region's constant, for element block + i.
  auto constant = [&](const double* per_region, std::size_t i) {
    return per_region[kUniform ? ru : v.region[block + i]];
  };

  // Fe = F·Fp⁻¹ (Fp⁻¹ stored column-major).
  const double(&elastic_deformation)[9][kViscousBlock] =
      kPlastic ? b.elastic_deformation : b.deformation;
#pragma omp simd
  for (std::size_t i = 0; i < (kPlastic ? count : 0); ++i) {
    const Matrix3 F = load_matrix(b.deformation, i);
#pragma GCC unroll 3
    for (int a = 0; a < 3; ++a)
#pragma GCC unroll 3
      for (int k = 0; k < 3; ++k)
        b.elastic_deformation[3 * a + k][i] =
            F.m[a][0] * history[(12 + 3 * k) * kViscousBlock + i] +
            F.m[a][1] * history[(13 + 3 * k) * kViscousBlock + i] +
            F.m[a][2] * history[(14 + 3 * k) * kViscousBlock + i];
  }

  // S_e = Fe⁻¹·P(Fe) = μI + U'(J)/J·cofᵀ·cof, with U'(J) = (λ ln J − μ)/J; then the arm
  // H = g·H_before + h·(S_e − S_e before).
  double min_j = min_j_out, max_j = max_j_out;
#pragma omp simd reduction(min : min_j) reduction(max : max_j)
  for (std::size_t i = 0; i < count; ++i) {
    const Matrix3 fe = load_matrix(elastic_deformation, i);
    const Matrix3 cof = cofactor(fe);
    const double J = fe.m[0][0] * cof.m[0][0] + fe.m[1][0] * cof.m[1][0] + fe.m[2][0] * cof.m[2][0];
    min_j = min_of(min_j, J);
    max_j = max_of(max_j, J);
    // Collapsed (flagged below): any finite value will do.
    const double safe_j = J >= kMinVolumeRatio ? J : 1.0;
    const double mu = constant(v.mu_pa, i), lambda = constant(v.lambda_pa, i);
    const double volumetric = (lambda * log_of(safe_j) - mu) / (safe_j * safe_j);
    // (cofᵀ·cof)_ac = column a of cof · column c of cof. Voigt: xx, yy, zz, yz, xz, xy.
    auto cc = [&](int a, int c) {
      return cof.m[0][a] * cof.m[0][c] + cof.m[1][a] * cof.m[1][c] + cof.m[2][a] * cof.m[2][c];
    };
    const double elastic[6] = {mu + volumetric * cc(0, 0), mu + volumetric * cc(1, 1),
                               mu + volumetric * cc(2, 2), volumetric * cc(1, 2),
                               volumetric * cc(0, 2),      volumetric * cc(0, 1)};
    const double decay = constant(v.arm_decay, i), loading = constant(v.arm_loading, i);
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {
      b.elastic_stress[k][i] = elastic[k];
      b.arm[k][i] = decay * history[k * kViscousBlock + i] +
                    loading * (elastic[k] - history[(6 + k) * kViscousBlock + i]);
    }
  }
  min_j_out = min_j;
  max_j_out = max_j;

  // S = g0·S_e + g1·H; the yield check on τ = Fe·S·Feᵀ; P = Fe·S·Fp⁻ᵀ.
#pragma omp simd
  for (std::size_t i = 0; i < count; ++i) {
    const Matrix3 fe = load_matrix(elastic_deformation, i);
    const double g0 = constant(v.relaxed_fraction, i), g1 = constant(v.arm_fraction, i);
    double pk2[6];
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) pk2[k] = g0 * b.elastic_stress[k][i] + g1 * b.arm[k][i];
    const double S[3][3] = {
        {pk2[0], pk2[5], pk2[4]}, {pk2[5], pk2[1], pk2[3]}, {pk2[4], pk2[3], pk2[2]}};
    double feS[3][3];
#pragma GCC unroll 3
    for (int a = 0; a < 3; ++a)
#pragma GCC unroll 3
      for (int k = 0; k < 3; ++k)
        feS[a][k] = fe.m[a][0] * S[0][k] + fe.m[a][1] * S[1][k] + fe.m[a][2] * S[2][k];
    auto tau = [&](int a, int c) {
      return feS[a][0] * fe.m[c][0] + feS[a][1] * fe.m[c][1] + feS[a][2] * fe.m[c][2];
    };
    const double t00 = tau(0, 0), t11 = tau(1, 1), t22 = tau(2, 2);
    const double t12 = tau(1, 2), t02 = tau(0, 2), t01 = tau(0, 1);
    const double mean = (t00 + t11 + t22) / 3.0;
    const double deviator_sq = (t00 - mean) * (t00 - mean) + (t11 - mean) * (t11 - mean) +
                               (t22 - mean) * (t22 - mean) +
                               2.0 * (t12 * t12 + t02 * t02 + t01 * t01);
    const double yield = constant(v.yield_limit_pa, i) + v.yield_raise_pa[block + i];
    const double J = fe.m[0][0] * (fe.m[1][1] * fe.m[2][2] - fe.m[2][1] * fe.m[1][2]) +
                     fe.m[1][0] * (fe.m[2][1] * fe.m[0][2] - fe.m[0][1] * fe.m[2][2]) +
                     fe.m[2][0] * (fe.m[0][1] * fe.m[1][2] - fe.m[1][1] * fe.m[0][2]);
    const bool general = !(J >= kMinVolumeRatio) | (1.5 * deviator_sq > yield * yield);
    v.needs_general[block + i] = general ? 1 : 0;
    b.flagged[i] = general ? 1.0 : 0.0;
    // (Fp⁻ᵀ)[k][j] = Fp⁻¹[j][k], stored in component 12 + j + 3k.
#pragma GCC unroll 3
    for (int a = 0; a < 3; ++a)
#pragma GCC unroll 3
      for (int j = 0; j < 3; ++j)
        b.stress[3 * a + j][i] = kPlastic ? feS[a][0] * history[(12 + j) * kViscousBlock + i] +
                                                feS[a][1] * history[(15 + j) * kViscousBlock + i] +
                                                feS[a][2] * history[(18 + j) * kViscousBlock + i]
                                          : feS[a][j];
  }

  // The dashpots' work over the step: V·Δt/τ·(ψ(H before) + ψ(H)) (trapezoid of 2ψ/τ), with
  // ψ = a·(H:H − b·(tr H)²); the commit (a flagged element keeps what it had for the general
  // update). A loop of its own: one loop with the stress held more values than there are registers.
#pragma omp simd
  for (std::size_t i = 0; i < count; ++i) {
    const bool general = b.flagged[i] != 0.0;
    double trace_before = 0.0, trace_after = 0.0, contraction_before = 0.0, contraction_after = 0.0;
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {
      const double weight = k < 3 ? 1.0 : 2.0;
      const double before = history[k * kViscousBlock + i], after = b.arm[k][i];
      trace_before += k < 3 ? before : 0.0;
      trace_after += k < 3 ? after : 0.0;
      contraction_before += weight * before * before;
      contraction_after += weight * after * after;
    }
    const double b_vol = constant(v.arm_energy_volumetric, i);
    const double work = rest_volume[block + i] * constant(v.step_over_relaxation_time, i) *
                        constant(v.arm_energy_scale, i) *
                        (contraction_before - b_vol * trace_before * trace_before +
                         contraction_after - b_vol * trace_after * trace_after);
    b.dashpot_work_j[i] = general ? 0.0 : work;
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {
      double& arm = history[k * kViscousBlock + i];
      double& elastic = history[(6 + k) * kViscousBlock + i];
      arm = general ? arm : b.arm[k][i];
      elastic = general ? elastic : b.elastic_stress[k][i];
    }
  }
  // Summed in element order after the loop: GCC 12 leaves this loop scalar when it carries a
  // simd reduction (measured), and the order makes the sum the same on every run.
  double dissipated = dissipated_out;
  for (std::size_t i = 0; i < count; ++i) dissipated += b.dashpot_work_j[i];
  dissipated_out = dissipated;
}

template <int kFibreFamilies>
void viscous_forces(const ViscousKernelData& data, std::size_t begin, std::size_t end,
                    ElasticKernelSeen& seen, double& dissipated_j) {
  const ElasticKernelData d = data.elastic;
  double min_j = seen.min_volume_ratio, max_j = seen.max_volume_ratio;
  double max_fibre = seen.max_fibre_modulus_pa, dissipated = 0.0;
  ViscousBlock b;
  for (std::size_t block = begin; block < end; block += kViscousBlock) {
    const std::size_t count = end - block < kViscousBlock ? end - block : kViscousBlock;
#pragma omp simd
    for (std::size_t i = 0; i < count; ++i) {
      const Matrix3 F = deformation_gradient(d, block + i);
#pragma GCC unroll 9
      for (int k = 0; k < 9; ++k) b.deformation[k][i] = F.m[k / 3][k % 3];
    }
    const std::int32_t first_region = data.region[block];
    bool uniform = true;
    for (std::size_t i = 1; i < count; ++i) uniform &= data.region[block + i] == first_region;
    const bool plastic = data.plastic_block[block / kViscousBlock] != 0;
    if (uniform && !plastic)
      viscous_law<true, false>(data, block, count, first_region, b, min_j, max_j, dissipated);
    else if (uniform)
      viscous_law<true, true>(data, block, count, first_region, b, min_j, max_j, dissipated);
    else if (!plastic)
      viscous_law<false, false>(data, block, count, first_region, b, min_j, max_j, dissipated);
    else
      viscous_law<false, true>(data, block, count, first_region, b, min_j, max_j, dissipated);
    if constexpr (kFibreFamilies > 0) {
#pragma omp simd reduction(max : max_fibre)
      for (std::size_t i = 0; i < count; ++i) {
        const Matrix3 F = load_matrix(b.deformation, i);
        double P[3][3] = {};
        max_fibre = max_of(max_fibre, add_fibre_stress<kFibreFamilies>(d, block + i, F, P));
#pragma GCC unroll 9
        for (int k = 0; k < 9; ++k) b.stress[k][i] += P[k / 3][k % 3];
      }
    }
#pragma omp simd
    for (std::size_t i = 0; i < count; ++i) {
      const Matrix3 P = load_matrix(b.stress, i);
      store_corner_forces(d, block + i, P.m);
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
