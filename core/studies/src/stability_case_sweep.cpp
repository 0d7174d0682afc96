// Case 12 of the stability suite (stability_suite.h): random valid parameter sets. A seeded sweep
// draws every tissue and model parameter from its documented range (parameter_ranges.h), switches
// the effects on or off at random, cycles through the integrators, and pulls a bar of the drawn
// tissue by an end traction, holds, and releases it. Every sample must stay finite, keep its
// energy books and stay within the bounds derived below.
#include "stability_cases.h"

#include "stability_runner.h"

#include "liversim/engine/model_building.h"
#include "liversim/engine/parameter_ranges.h"
#include "liversim/meshing/box_mesh.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <random>
#include <string>

namespace liversim::detail {
namespace {

// The books' tolerance is every case's (kEnergyTolerance, stability_runner.h); viscous samples add
// what the books' Maxwell-arm energy may be off by at the strain reached (arm_books_uncertainty_j).

// A 4 × 2 × 2 cm bar in 1 cm cubes (96 tetrahedra), fixed at x = 0, pulled at x = kLength.
constexpr double kLength = 0.04;
constexpr double kInterval = 0.01;
constexpr int kHoldIntervals = 25;  // the pull is held for 0.25 s ...
constexpr int kFreeIntervals = 25;  // ... then the bar is free for 0.25 s
constexpr double kHoldS = kInterval * kHoldIntervals;

// A uniform fraction in (0, 1) from 32 bits of the generator. std::mt19937's sequence is fixed by
// the standard, its distributions are not: this keeps a seed's samples the same on every platform.
double uniform(std::mt19937& rng) {
  return (static_cast<double>(rng()) + 0.5) * 0x1p-32;
}
bool coin(std::mt19937& rng) {
  return uniform(rng) < 0.5;
}
double draw(std::mt19937& rng, std::string_view name) {
  return parameter_range(name).at_fraction(uniform(rng));
}

struct Sample {
  IntegratorKind kind = IntegratorKind::central_difference;
  double step_s = 0.0;
  RegionMaterial parenchyma;
  double lesion_ratio = 0.0;  // 0: no lesion
  bool average_nodal_pressure = false;
  double mass_damping_per_s = 0.0;
  std::vector<Eigen::Vector3d> first_family, second_family;
  double target_strain = 0.0;
  double traction_pa = 0.0;
};

// Every parameter is drawn for every sample, in a fixed order, whether its effect is on or not:
// a sample's values then depend on the seed and its index only.
Sample draw_sample(std::mt19937& rng, int index) {
  namespace p = parameter;
  Sample s;
  const double youngs = draw(rng, p::youngs_modulus), poisson = draw(rng, p::poisson_ratio);
  const double density = draw(rng, p::density), fraction = draw(rng, p::mooney_rivlin_fraction);
  const ViscoelasticParameters ve{draw(rng, p::e1), draw(rng, p::e2), draw(rng, p::eta1)};
  const double yield = draw(rng, p::yield_limit), eta2 = draw(rng, p::eta2);
  const ViscoplasticParameters vp{yield, eta2, draw(rng, p::creep_index)};
  const FibreParameters fibres{draw(rng, p::fibre_k1), draw(rng, p::fibre_k2)};
  s.mass_damping_per_s = draw(rng, p::mass_damping);
  const double lesion_ratio = draw(rng, p::lesion_stiffness_ratio);
  // Effects: viscoplasticity needs viscoelasticity (it acts in series with it); Mooney-Rivlin is
  // for elastic regions only (build_model rejects it with viscoelasticity).
  const bool plastic = coin(rng), viscous = plastic || coin(rng);
  const bool with_fibres = coin(rng), two_families = coin(rng);
  s.average_nodal_pressure = coin(rng);
  const bool mooney_rivlin = coin(rng), lesion = coin(rng);
  s.target_strain = 0.1 + 0.1 * uniform(rng);
  const double step_fraction = uniform(rng);
  // Fibres within ~35° of the pull, so that the pull stretches them.
  const Eigen::Vector3d tilt(0.0, uniform(rng) - 0.5, uniform(rng) - 0.5);

  s.kind = kAllIntegrators[static_cast<std::size_t>(index) % kAllIntegrators.size()];
  // Implicit schemes need a step: 1–2 ms, a haptic-to-visual rate. Explicit ones take their
  // stable step (dopri5 starts there and adapts).
  s.step_s = is_explicit(s.kind) ? 0.0 : 1e-3 * (1.0 + step_fraction);
  s.parenchyma.tissue = TissueMaterial{viscous ? ve.instantaneous_modulus_pa() : youngs, poisson,
                                       density, mooney_rivlin && !viscous ? fraction : 0.0};
  if (viscous) s.parenchyma.viscoelastic = ve;
  if (plastic) s.parenchyma.viscoplastic = vp;
  if (with_fibres) {
    s.parenchyma.fibres = fibres;
    s.first_family = {Eigen::Vector3d::UnitX() + tilt};
    if (two_families) s.second_family = {Eigen::Vector3d::UnitX() - tilt};
  }
  s.lesion_ratio = lesion ? lesion_ratio : 0.0;

  // The traction: the nominal stress that would strain the parenchyma by target_strain at the end
  // of the hold, by its most compliant response: the relaxed modulus (E2 when viscous) plus the
  // creep of the hold above zero yield, T^n/η2 (Eq. 4). Fibres, the lesion and a yield limit only
  // make the bar stiffer; Mooney-Rivlin keeps the small-strain moduli.
  double compliance = 1.0 / (viscous ? ve.e2_pa : youngs);
  if (plastic) compliance += std::pow(kHoldS, vp.creep_index_n) / vp.eta2_pa_s_pow_n;
  s.traction_pa = s.target_strain / compliance;
  return s;
}

// The lesion: a tumour, isotropic and elastic (as in case 5): the parenchyma's instantaneous
// modulus times the ratio, its Poisson's ratio, density and Mooney-Rivlin fraction. (Scaling its
// fibres or viscosities too would leave their documented ranges: the ratio covers E only.)
RegionMaterial lesion_of(const RegionMaterial& parenchyma, double ratio) {
  RegionMaterial lesion;
  lesion.tissue = parenchyma.tissue;
  lesion.tissue.youngs_modulus_pa *= ratio;
  return lesion;
}

// ½·S : C⁻¹ : S for the isotropic small-strain stiffness C = 2μ·I + λ·1⊗1 (as energy.cpp).
double small_strain_energy_density(const Eigen::Matrix3d& S, double mu, double lambda) {
  return (S.squaredNorm() - lambda / (2.0 * mu + 3.0 * lambda) * S.trace() * S.trace()) /
         (4.0 * mu);
}

// The energy books count the Maxwell arm's spring as ½·g1·H : C⁻¹ : H with C the instantaneous
// small-strain stiffness (energy.h): exact at small strain only, the arm's finite-strain law having
// no closed-form potential. An unrelaxed arm (long τ) carries H = S_e(Fe), the 2nd Piola–Kirchhoff
// stress of the Neo-Hookean base, and then holds exactly g1·ψ(Fe): the relative difference of the
// two at the element's Fe (of the order of the strain) is the books' relative error there. Applied
// to the arm energy the books hold and summed over the elements, it is what they may be off by.
double arm_books_uncertainty_j(const SimModel& model, const SimState& state) {
  if (!model.effects.viscous) return 0.0;
  double total = 0.0;
  for (std::size_t e = 0; e < model.tet_count; ++e) {
    const auto& law = model.viscous_parameters[static_cast<std::size_t>(model.region[e])];
    if (!law) continue;
    const double mu = model.shear_modulus_pa[e], lambda = model.lame_lambda_pa[e];
    const double arm_fraction =
        law->viscoelastic.e1_pa / law->viscoelastic.instantaneous_modulus_pa();
    const Eigen::Matrix3d Fe = deformation_gradient(model, state.position_m, e) *
                               state.viscous_history.inverse_plastic_deformation(e);
    const double J = Fe.determinant();
    if (!(J > neo_hookean::kMinVolumeRatio)) continue;  // the arm is frozen there
    const Eigen::Matrix3d inverse_c = (Fe.transpose() * Fe).inverse();
    const Eigen::Matrix3d S =
        mu * (Eigen::Matrix3d::Identity() - inverse_c) + lambda * std::log(J) * inverse_c;
    const double unrelaxed = small_strain_energy_density(S, mu, lambda);
    if (!(unrelaxed > 0.0)) continue;
    const double relative_error =
        std::abs(unrelaxed - neo_hookean::energy_density(Fe, mu, lambda)) / unrelaxed;
    const Voigt6 h = state.viscous_history.maxwell_stress_pa(e);  // Voigt: xx, yy, zz, yz, xz, xy
    Eigen::Matrix3d H;
    H << h[0], h[5], h[4], h[5], h[1], h[3], h[4], h[3], h[2];
    total += model.rest_volume_m3[e] * arm_fraction * small_strain_energy_density(H, mu, lambda) *
             relative_error;
  }
  return total;
}

std::string describe(int index, const Sample& s) {
  const RegionMaterial& m = s.parenchyma;
  char buffer[160];
  std::string text;
  auto add = [&](const char* format, auto... values) {
    std::snprintf(buffer, sizeof buffer, format, values...);
    text += buffer;
  };
  add("#%02d %s", index, std::string(integrator_name(s.kind)).c_str());
  if (s.step_s > 0.0) add(" Δt=%.2gms", 1e3 * s.step_s);
  add(" E=%.3gkPa ν=%.3f ρ=%.0f α=%.2g/s pull=%.3gPa(ε≈%.2f)", 1e-3 * m.tissue.youngs_modulus_pa,
      m.tissue.poisson_ratio, m.tissue.density_kg_per_m3, s.mass_damping_per_s, s.traction_pa,
      s.target_strain);
  if (m.tissue.mooney_rivlin_fraction > 0.0) add(" MR=%.2f", m.tissue.mooney_rivlin_fraction);
  if (m.viscoelastic)
    add(" VE(E1=%.3g E2=%.3g η1=%.3g)", m.viscoelastic->e1_pa, m.viscoelastic->e2_pa,
        m.viscoelastic->eta1_pa_s);
  if (m.viscoplastic)
    add(" VP(σs=%.3g η2=%.3g n=%.2f)", m.viscoplastic->yield_limit_pa,
        m.viscoplastic->eta2_pa_s_pow_n, m.viscoplastic->creep_index_n);
  if (m.fibres)
    add(" HGO%s(k1=%.3g k2=%.3g)", s.second_family.empty() ? "" : "×2", m.fibres->k1_pa,
        m.fibres->k2);
  if (s.average_nodal_pressure) text += " ANP";
  if (s.lesion_ratio > 0.0) add(" lesion×%.3g", s.lesion_ratio);
  return text;
}

StabilityRun sweep_run(int index, const Sample& sample) {
  TetMesh mesh = box_mesh(4, 2, 2, {kLength, 0.02, 0.02});
  ModelOptions options;
  options.regions[0] = sample.parenchyma;
  if (sample.lesion_ratio > 0.0) {  // the slab 2 cm < x < 3 cm, as in case 5
    for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
      double centre_x = 0.0;
      for (int c = 0; c < 4; ++c) centre_x += 0.25 * mesh.rest_position_m.x[mesh.corner[c][e]];
      if (centre_x > 0.02 && centre_x < 0.03) mesh.region[e] = 1;
    }
    options.regions.push_back(lesion_of(sample.parenchyma, sample.lesion_ratio));
  }
  options.fibre_field.first_family = sample.first_family;
  options.fibre_field.second_family = sample.second_family;
  options.average_nodal_pressure = sample.average_nodal_pressure;
  options.fixed_nodes = nodes_on_plane(mesh, 0, 0.0);
  options.mass_damping_per_s = sample.mass_damping_per_s;
  options.integrator.kind = sample.kind;
  options.integrator.step_s = sample.step_s;
  const SimModel model = build_model(mesh, options);

  std::vector<PointLoad> pull;
  for (const PointLoad& load : end_face_tension(mesh, sample.traction_pa))
    if (load.force_n.x() > 0.0) pull.push_back(load);  // the free end only

  BookedRun run(model, describe(index, sample));
  double smallest_volume_ratio = std::numeric_limits<double>::infinity();
  auto track = [&] {
    for (std::size_t e = 0; e < model.tet_count; ++e)
      smallest_volume_ratio =
          std::min(smallest_volume_ratio,
                   deformation_gradient(model, run.state.position_m, e).determinant());
  };
  double books_uncertainty = 0.0;  // largest arm_books_uncertainty_j / energy supplied
  auto books = [&] {
    const double supplied = run.balance().supplied_j();
    if (supplied > 0.0)
      books_uncertainty =
          std::max(books_uncertainty, arm_books_uncertainty_j(model, run.state) / supplied);
  };
  bool going = true;
  for (int i = 0; i < kHoldIntervals && going; ++i)
    if ((going = run.advance({pull, {}}, kInterval))) track(), books();
  const double released = run.held_j();
  const double uncertain_at_release = arm_books_uncertainty_j(model, run.state);
  for (int i = 0; i < kFreeIntervals && going; ++i)
    if ((going = run.advance({}, kInterval))) track(), books();
  const double energy_tolerance = kEnergyTolerance + books_uncertainty;
  // The allowance is reported as a check: at 1 (the whole energy supplied) the books could no
  // longer tell anything, and the case would prove nothing about energy.
  run.check("books' arm-energy uncertainty / energy supplied (added to the tolerance)",
            books_uncertainty, 1.0);

  // A moderate pull inverts nothing: the physical law holds above neo_hookean::kMinVolumeRatio
  // (below it the volumetric energy is a Taylor continuation, a guard, not the tissue).
  run.check("smallest element volume ratio J", smallest_volume_ratio, neo_hookean::kMinVolumeRatio,
            false);
  // After the release nothing supplies energy: what the bar holds can only be dissipated (by
  // damping, viscosity, flow), up to the books' tolerance and their arm-energy uncertainty at
  // either end.
  run.check("held energy at the end / at release", run.held_j() / released,
            1.0 + kEnergyTolerance +
                (uncertain_at_release + arm_books_uncertainty_j(model, run.state)) / released);
  // Implicit steps at 1–2 ms and strains ≤ ~25 % are well within Newton's reach.
  run.check("unconverged implicit steps", run.result().steps.unconverged_steps, 0.0);
  // Displacement: the traction's static strain is ≤ target_strain ≤ 0.2 at small strain, ≤ 0.25
  // with the finite-strain softening of Neo-Hookean tension (nominal stress μ(λ − λ⁻²) at ν → ½);
  // a suddenly applied constant load overshoots its static displacement at most twice (undamped
  // linear oscillator). The far end then moves ≤ 0.5 L; the bound L leaves a factor 2 for what the
  // estimate leaves out (creep under the overshoot, lateral motion).
  return run.finish(kLength, energy_tolerance);
}

}  // namespace

std::vector<StabilityRun> parameter_sweep_case(const StabilitySuiteOptions& options) {
  std::mt19937 rng(options.sweep_seed);
  std::vector<StabilityRun> runs;
  for (int i = 0; i < options.sweep_samples; ++i) {
    const Sample sample = draw_sample(rng, i);
    try {
      runs.push_back(sweep_run(i, sample));
    } catch (const std::exception& error) {  // one sample's failure must not hide the others
      StabilityRun failed;
      failed.variant = describe(i, sample);
      failed.integrator = std::string(integrator_name(sample.kind));
      failed.error = error.what();
      runs.push_back(failed);
    }
  }
  return runs;
}

}  // namespace liversim::detail
