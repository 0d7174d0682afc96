// The vectorised element kernels, each instruction-set build of them, against the laws of
// material.cpp and fibres.cpp element by element: stretched, compressed below the volumetric
// continuation's J0, inverted, and fibres past the exponential's guard. Enough elements that the
// vector body and the remainder loop both run.
#include "../../core/engine/src/element_kernels.h"

#include "liversim/engine/fibres.h"
#include "liversim/engine/material.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <array>
#include <random>
#include <vector>

namespace liversim {
namespace {

struct Element {
  Eigen::Matrix3d F;
  double mu, lambda, k1, k2, nodal_pressure;
  Eigen::Vector3d a;
};

std::vector<Element> elements() {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Element> out;
  auto add = [&](Eigen::Matrix3d F, double fibre_stretch_scale) {
    Element e;
    e.F = F;
    e.mu = 1000.0 + 500.0 * u(random);
    e.lambda = 50'000.0 + 20'000.0 * u(random);
    e.k1 = 2000.0 * (1.0 + u(random));
    e.k2 = 10.0 * fibre_stretch_scale;
    e.nodal_pressure = 300.0 * u(random);
    e.a = Eigen::Vector3d(u(random), u(random), u(random)).normalized();
    out.push_back(e);
  };
  for (int i = 0; i < 9; ++i)  // moderate strains: J near 1, fibres under and over stretch
    add(Eigen::Matrix3d::Identity() + 0.2 * Eigen::Matrix3d::NullaryExpr([&] { return u(random); }),
        1.0);
  add(Eigen::Vector3d(0.5, 0.5, 0.6).asDiagonal(), 1.0);    // J = 0.15 < J0: continuation
  add(Eigen::Vector3d(-0.8, 1.0, 0.7).asDiagonal(), 1.0);   // inverted, J < 0
  add(Eigen::Vector3d(2.5, 1.0, 1.0).asDiagonal(), 5.0);    // k2 (I4 − 1)² = 138 (a along x)
  add(Eigen::Vector3d(1.3, 0.9, 0.95).asDiagonal(), 11.0);  // 52: just past the guard
  out[out.size() - 2].a = out.back().a = Eigen::Vector3d::UnitX();
  add(Eigen::Matrix3d::Identity(), 1.0);  // rest
  return out;
}

// −V·P·Dm⁻ᵀ for Dm = I, V = 1: the forces on corners 1..3 are −P's columns.
Eigen::Matrix3d reference_stress(const Element& e, bool fibres, bool averaged) {
  Eigen::Matrix3d P = averaged ? neo_hookean::first_piola_stress_given_lambda_pressure(
                                     e.F, e.mu, e.lambda, e.nodal_pressure)
                               : neo_hookean::first_piola_stress(e.F, e.mu, e.lambda);
  if (fibres) P += hgo::first_piola_stress(e.F, e.a, FibreParameters{e.k1, e.k2});
  return P;
}

TEST(ElementKernels, EachInstructionSetBuildFollowsTheLaws) {
  const std::vector<Element> set = elements();
  const std::size_t n = set.size();
  // Element i has its own four nodes: X0 = 0, X1..3 = unit vectors, so Dm = I and x = F·X.
  std::vector<std::int32_t> corners[4];
  std::vector<double> x(4 * n), y(4 * n), z(4 * n), pressure(4 * n);
  std::vector<double> identity[9], volume(n, 1.0), mu(n), lambda(n), fibre_parameters(2 * n),
      direction(3 * n);
  std::vector<double> force[4][3];
  for (int k = 0; k < 9; ++k) identity[k].assign(n, k % 4 == 0 ? 1.0 : 0.0);
  for (auto& corner : force)
    for (auto& axis : corner) axis.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const Element& e = set[i];
    for (int c = 0; c < 4; ++c) {
      const auto node = static_cast<std::int32_t>(4 * i + c);
      corners[c].push_back(node);
      const Eigen::Vector3d p = c == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(e.F.col(c - 1));
      x[node] = p.x();
      y[node] = p.y();
      z[node] = p.z();
      pressure[node] = e.nodal_pressure;
    }
    mu[i] = e.mu;
    lambda[i] = e.lambda;
    fibre_parameters[2 * i] = e.k1;
    fibre_parameters[2 * i + 1] = e.k2;
    for (int k = 0; k < 3; ++k) direction[3 * i + k] = e.a[k];
  }
  detail::ElasticKernelData data{};
  for (int c = 0; c < 4; ++c) data.corner[c] = corners[c].data();
  data.x = x.data();
  data.y = y.data();
  data.z = z.data();
  for (int k = 0; k < 9; ++k) data.dm_inverse[k] = identity[k].data();
  data.rest_volume_m3 = volume.data();
  data.shear_modulus_pa = mu.data();
  data.lame_lambda_pa = lambda.data();
  data.nodal_lambda_pressure_pa = pressure.data();
  data.fibre_parameters = fibre_parameters.data();
  data.fibre_direction[0] = direction.data();
  for (int c = 0; c < 4; ++c)
    for (int i = 0; i < 3; ++i) data.corner_force[c][i] = force[c][i].data();

  for (const detail::ElasticKernels* build :
       {&detail::generic::elastic_kernels(), &detail::avx2::elastic_kernels()})
    for (int fibres = 0; fibres < 2; ++fibres)
      for (int averaged = 0; averaged < 2; ++averaged) {
        detail::ElasticKernelSeen seen{1e300, -1e300, 0.0};
        build->forces[fibres][averaged](data, 0, n, seen);
        double min_j = 1e300;
        for (std::size_t i = 0; i < n; ++i) {
          const Eigen::Matrix3d P = reference_stress(set[i], fibres, averaged);
          min_j = std::min(min_j, set[i].F.determinant());
          Eigen::Matrix3d h, h0;
          for (int c = 0; c < 3; ++c)
            for (int a = 0; a < 3; ++a) h(a, c) = force[c + 1][a][i];
          // Round-off of a few dozen operations on entries of order |P| (the fibres' exp(50)
          // included): relative 1e-13.
          const double scale = std::max(1.0, P.norm());
          EXPECT_LE((h + P).norm(), 1e-13 * scale)
              << build->instruction_set << ", element " << i << ", fibres " << fibres
              << ", averaged " << averaged << "\nP =\n"
              << P << "\nkernel −h =\n"
              << -h;
          const Eigen::Vector3d balance(force[0][0][i], force[0][1][i], force[0][2][i]);
          EXPECT_LE((balance + h.rowwise().sum()).norm(), 1e-13 * scale);
        }
        EXPECT_NEAR(seen.min_volume_ratio, min_j, 1e-14);
        if (fibres) {
          EXPECT_GT(seen.max_fibre_modulus_pa, 1e20);  // the guarded element: k1·e⁵⁰·…
        }
      }
}

}  // namespace
}  // namespace liversim
