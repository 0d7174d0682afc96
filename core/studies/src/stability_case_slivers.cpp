// Case 3 of the stability suite (stability_suite.h): sliver and near-degenerate elements, flattened
// on purpose, and zero-volume elements, built in memory and imported from a file.
//
// The mesh: a free bar of 4 × 2 × 2 cubes (h = 1 cm, Kuhn subdivision) whose one interior node P
// is pushed to within δ·h (δ = 10⁻³) of the plane of a face of its star (the rhombus x = 3h, made
// of two triangles of the Kuhn subdivision). The two elements on that rhombus become a cap (P over
// the inside of its face) and a sliver (the four corners nearly coplanar, a convex quadrilateral):
// both of height δ·h at P, both of positive volume. The neighbours of P stay fair, because P stays
// inside the kernel of its (convex) star.
//
// What the mathematics says, and the checks made of it:
// - The stable step. A trial vector moving P alone bounds the largest eigenfrequency from below
//   (Rayleigh): ω_max² ≥ λ_max(K_PP)/m_P, and each flattened element adds V(λ+2μ)/h_P² ≈
//   (λ+2μ)A/(3h_P) to K_PP along the face's normal. So the step must shrink at least as √(h_P/h):
//   not as h_P/h, because P's lumped mass comes mostly from its fair neighbours. The element-by-
//   element bound (ω_max ≤ max_e ω_e with the element's own lumped mass) bounds ω_max from above,
//   so the step from below: it may not shrink more than the classical estimate, step ∝ h_min.
// - The answer. A linear-tetrahedron mesh passes the patch test whatever the shapes of its
//   elements: under a uniform nominal traction σ on both ends of a free bar, the homogeneous
//   stretch (F = diag(a, b, b), P₁₁ = σ, P₂₂ = 0) is an exact discrete equilibrium, slivers or not,
//   since the consistent end loads (end_face_tension) are exactly those of the uniform stress. The
//   bar gets there dynamically: the load ramps up in increments, each exciting modal transients of
//   at most its share of the static answer (the participation factors of the end displacement are
//   positive and sum to 1), which mass damping α shrinks as e^(−αt/2)/√(1 − ζ²). So after holding
//   the load for t_h the stretch is within e^(−α t_h/2)/√(1 − ζ₁²) of the exact one (ζ₁ = α/2ω₁,
//   ω₁ = π√(E/ρ)/L the bar's first axial mode; higher modes decay as fast and have smaller ζ).
//   Released, it comes back to its rest length within twice (a − 1)·e^(−α t_f/2) (the factor 2
//   covers the transient and velocity at release, each far smaller).
// - Zero volume. Pushing P exactly onto the rhombus (δ = 0) gives the two elements zero volume:
//   build_model must refuse the mesh and name the first, and the Abaqus reader must refuse the
//   same mesh written to a file and name the element and its line; the δ = 10⁻³ mesh written the
//   same way must be read back and run.
#include "stability_cases.h"

#include "stability_runner.h"

#include "liversim/engine/material.h"
#include "liversim/engine/mesh_io.h"
#include "liversim/engine/mesh_quality.h"
#include "liversim/engine/model_building.h"
#include "liversim/meshing/box_mesh.h"

#include <Eigen/Eigenvalues>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <system_error>

namespace liversim::detail {
namespace {

constexpr double kLength = 0.04, kCell = 0.01;  // 4 × 2 × 2 cubes of 1 cm
constexpr double kFlatness = 1e-3;              // δ: the height of the flattened elements / h
constexpr double kDamping = 30.0;               // α (1/s)
constexpr double kTraction = 100.0;             // σ (Pa): about 3 % stretch
constexpr int kRampIntervals = 10;              // the load ramps up over 10 × 10 ms
constexpr double kRampInterval = 0.01;
constexpr double kHold = 0.3, kFree = 0.3;  // held, then released (s)

const TissueMaterial kTissue{3500.0, 0.45, 1060.0};

// Node (i, j, k) of box_mesh(4, 2, 2, ...).
NodeIndex grid_node(int i, int j, int k) {
  return i + 5 * (j + 3 * k);
}
const NodeIndex kPushed = grid_node(2, 1, 1);

// The bar with P = node (2, 1, 1) pushed towards the rhombus x = 3h of its star (corners (3,1,1),
// (3,2,1), (3,1,2), (3,2,2)), ending δ·h from its plane, over the centroid of its triangle
// (3,1,1)–(3,2,1)–(3,2,2). With δ = 0 it lies exactly in that plane (its x copied from a corner's).
TetMesh pushed_bar(double flatness) {
  TetMesh mesh = box_mesh(4, 2, 2, {kLength, 0.02, 0.02});
  const Eigen::Vector3d corner = mesh.rest_position_m.at(grid_node(3, 1, 1));
  const Eigen::Vector3d p(corner.x() - flatness * kCell, corner.y() + 2.0 * kCell / 3.0,
                          corner.z() + kCell / 3.0);
  mesh.rest_position_m.set(kPushed, p);
  return mesh;
}

ModelOptions bar_options(IntegratorKind kind) {
  ModelOptions options;
  options.regions[0].tissue = kTissue;
  options.mass_damping_per_s = kDamping;  // no fixed node: a free bar pulled at both ends
  options.integrator.kind = kind;
  options.integrator.step_s = is_explicit(kind) ? 0.0 : 2e-3;
  return options;
}

// The explicit step the engine takes for a largest frequency ω (integrator.h: damping shortens
// it); decreasing in ω.
double step_for(const SimModel& model, double omega) {
  const double xi = model.mass_damping_per_s / (2.0 * omega);
  return model.stable_step_safety * (2.0 / omega) * (std::sqrt(1.0 + xi * xi) - xi);
}

// Shape-function gradients of element e at rest (rows of Dm⁻¹, and minus their sum).
std::array<Eigen::Vector3d, 4> gradients(const TetMesh& mesh, std::size_t e) {
  const auto n = mesh.tet(e);
  Eigen::Matrix3d dm;
  for (int c = 1; c < 4; ++c)
    dm.col(c - 1) = mesh.rest_position_m.at(n[c]) - mesh.rest_position_m.at(n[0]);
  const Eigen::Matrix3d inv = dm.inverse();
  std::array<Eigen::Vector3d, 4> g;
  for (int c = 1; c < 4; ++c) g[c] = inv.row(c - 1).transpose();
  g[0] = -(g[1] + g[2] + g[3]);
  return g;
}

// Block (a, b) of the element's small-strain stiffness (the Neo-Hookean tangent at rest):
// V (μ (g_a·g_b) I + λ g_a g_bᵀ + μ g_b g_aᵀ).
Eigen::Matrix3d stiffness_block(const Eigen::Vector3d& ga, const Eigen::Vector3d& gb,
                                double volume) {
  const double mu = kTissue.shear_modulus_pa(), lambda = kTissue.lame_lambda_pa();
  return volume * (mu * ga.dot(gb) * Eigen::Matrix3d::Identity() + lambda * ga * gb.transpose() +
                   mu * gb * ga.transpose());
}

// Rayleigh's lower bound on ω_max: the best trial vector that moves node p alone.
double rayleigh_lower_bound(const TetMesh& mesh, const SimModel& model, NodeIndex p) {
  Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    const auto n = mesh.tet(e);
    for (int c = 0; c < 4; ++c)
      if (n[c] == p) {
        const auto g = gradients(mesh, e);
        k += stiffness_block(g[c], g[c], mesh.rest_volume_m3(e));
      }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(k);
  return std::sqrt(eigen.eigenvalues().maxCoeff() / model.lumped_mass_kg[p]);
}

// The element-by-element upper bound on ω_max: max over elements of λ_max(K_e) / (ρ V_e / 4).
double element_upper_bound(const TetMesh& mesh) {
  double largest = 0.0;
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    const auto g = gradients(mesh, e);
    const double volume = mesh.rest_volume_m3(e);
    Eigen::Matrix<double, 12, 12> k;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) k.block<3, 3>(3 * a, 3 * b) = stiffness_block(g[a], g[b], volume);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>> eigen(k);
    largest = std::max(largest,
                       eigen.eigenvalues().maxCoeff() / (kTissue.density_kg_per_m3 * volume / 4.0));
  }
  return std::sqrt(largest);
}

// The homogeneous stretch a of a free Neo-Hookean bar under nominal end traction σ: F = diag(a,
// b, b) with P₁₁ = σ and P₂₂ = 0 (bisection on each, both monotone).
double exact_stretch(double sigma) {
  const double mu = kTissue.shear_modulus_pa(), lambda = kTissue.lame_lambda_pa();
  auto stress = [&](double a, double b) {
    const Eigen::Matrix3d F = Eigen::Vector3d(a, b, b).asDiagonal();
    return neo_hookean::first_piola_stress(F, mu, lambda);
  };
  auto lateral = [&](double a) {  // b with P₂₂(a, b) = 0: P₂₂ grows with b
    double low = 0.5, high = 1.5;
    for (int i = 0; i < 100; ++i) {
      const double mid = 0.5 * (low + high);
      (stress(a, mid)(1, 1) > 0.0 ? high : low) = mid;
    }
    return 0.5 * (low + high);
  };
  double low = 1.0, high = 2.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (low + high);
    (stress(mid, lateral(mid))(0, 0) > sigma ? high : low) = mid;
  }
  return 0.5 * (low + high);
}

double stretch_of(const TetMesh& mesh, const NodeArray& position) {
  return (mean_coordinate_on_plane(mesh, position, 0, kLength) -
          mean_coordinate_on_plane(mesh, position, 0, 0.0)) /
         kLength;
}

std::vector<PointLoad> scaled(const std::vector<PointLoad>& loads, double factor) {
  std::vector<PointLoad> out = loads;
  for (PointLoad& load : out) load.force_n *= factor;
  return out;
}

// A file in the temporary directory with a name no other run uses, removed when done.
class TemporaryFile {
 public:
  explicit TemporaryFile(const std::string& stem) {
    std::random_device random;
    const auto now = std::chrono::steady_clock::now().time_since_epoch().count();
    path_ =
        std::filesystem::temp_directory_path() /
        ("liversim-" + stem + "-" + std::to_string(now) + "-" + std::to_string(random()) + ".inp");
  }
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  ~TemporaryFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Writes the mesh as an Abaqus input file (ids from 1, coordinates to the last bit) and returns
// the 1-based line of element e's data line.
int write_abaqus(const TetMesh& mesh, const std::filesystem::path& file, std::size_t e) {
  std::ofstream out(file);
  if (!out) throw std::runtime_error("cannot write " + file.string());
  out << std::setprecision(17);
  out << "*Heading\nLiverSim stability case 3\n*Node\n";  // lines 1–3
  for (std::size_t n = 0; n < mesh.node_count(); ++n) {
    const Eigen::Vector3d p = mesh.rest_position_m.at(n);
    out << n + 1 << ", " << p.x() << ", " << p.y() << ", " << p.z() << '\n';
  }
  out << "*Element, type=C3D4\n";  // line node_count + 4
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const auto c = mesh.tet(t);
    out << t + 1 << ", " << c[0] + 1 << ", " << c[1] + 1 << ", " << c[2] + 1 << ", " << c[3] + 1
        << '\n';
  }
  out.close();
  if (!out) throw std::runtime_error("cannot write " + file.string());
  return static_cast<int>(mesh.node_count() + 5 + e);
}

bool mentions(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// δ = 0: the flattened mesh refused in memory and from a file; the sliver mesh read back and run.
StabilityRun zero_volume_run() {
  const TetMesh flat = pushed_bar(0.0);
  std::size_t first_zero = flat.tet_count();
  int zero_count = 0;
  for (std::size_t e = 0; e < flat.tet_count(); ++e)
    if (flat.rest_volume_m3(e) == 0.0) {
      first_zero = std::min(first_zero, e);
      ++zero_count;
    }

  bool model_refused = false;
  std::string model_error;
  try {
    build_model(flat, bar_options(IntegratorKind::central_difference));
  } catch (const std::invalid_argument& error) {
    model_error = error.what();
    model_refused =
        mentions(model_error, "element " + std::to_string(first_zero) + " has zero volume");
  }

  bool file_refused = false;
  {
    const TemporaryFile file("case3-zero-volume");
    const int line = write_abaqus(flat, file.path(), first_zero);
    try {
      read_tet_mesh(file.path());
    } catch (const MeshReadError& error) {
      file_refused =
          error.line() == line &&
          mentions(error.what(), "element " + std::to_string(first_zero + 1) + " (line " +
                                     std::to_string(line) + ") has zero volume");
    }
  }

  const TetMesh sliver = pushed_bar(kFlatness);
  TetMesh read_back;
  {
    const TemporaryFile file("case3-slivers");
    write_abaqus(sliver, file.path(), 0);
    read_back = read_tet_mesh(file.path());  // throws (and the case fails) if refused
  }
  double largest_move = 0.0;
  for (std::size_t n = 0; n < sliver.node_count(); ++n)
    largest_move = std::max(
        largest_move, (read_back.rest_position_m.at(n) - sliver.rest_position_m.at(n)).norm());

  const SimModel model = build_model(read_back, bar_options(IntegratorKind::backward_euler));
  BookedRun run(model, "zero-volume elements (δ = 0), and the sliver mesh read from a file");
  run.check("elements of zero volume in the flattened mesh", zero_count, 1.0, false);
  run.check("build_model refused it, naming element " + std::to_string(first_zero) + " (1 = yes)",
            model_refused ? 1.0 : 0.0, 1.0, false);
  run.check("the Abaqus reader refused it, naming element " + std::to_string(first_zero + 1) +
                " and its line (1 = yes)",
            file_refused ? 1.0 : 0.0, 1.0, false);
  run.check("sliver mesh read back: largest node move (m)", largest_move, 0.0);
  run.check("sliver mesh read back: elements", read_back.tet_count(), sliver.tet_count(), false);
  const std::vector<PointLoad> loads = end_face_tension(read_back, kTraction);
  run.advance({loads, {}}, 0.01, 10);
  run.check("unconverged implicit steps", run.result().steps.unconverged_steps, 0.0);
  return run.finish(kLength, kEnergyTolerance);
}

}  // namespace

std::vector<StabilityRun> sliver_elements_case(const StabilitySuiteOptions&) {
  const TetMesh fair = box_mesh(4, 2, 2, {kLength, 0.02, 0.02});
  const TetMesh mesh = pushed_bar(kFlatness);
  const MeshQualityReport quality = assess_quality(mesh);
  const SimModel fair_model = build_model(fair, bar_options(IntegratorKind::central_difference));

  const std::vector<PointLoad> loads = end_face_tension(mesh, kTraction);
  const double exact = exact_stretch(kTraction);
  const double first_mode =
      M_PI * std::sqrt(kTissue.youngs_modulus_pa / kTissue.density_kg_per_m3) / kLength;
  const double zeta = kDamping / (2.0 * first_mode);
  const double transient = std::exp(-0.5 * kDamping * kHold) / std::sqrt(1.0 - zeta * zeta);

  std::vector<StabilityRun> runs;
  for (IntegratorKind kind : {IntegratorKind::central_difference, IntegratorKind::backward_euler}) {
    const SimModel model = build_model(mesh, bar_options(kind));  // slivers are valid elements
    BookedRun run(model, std::string(integrator_name(kind)) + ", δ = 1e-3");
    if (is_explicit(kind)) {
      run.check("largest aspect ratio R/3r", quality.max_aspect_ratio, 100.0, false);
      run.check("smallest element height / cell edge", quality.min_height_m / kCell,
                1.001 * kFlatness);
      run.check("inverted or degenerate elements",
                static_cast<double>(quality.inverted_count + quality.degenerate_count), 0.0);
      // Bounded from above by the pushed node's Rayleigh quotient (∝ √h_min), from below by the
      // element-by-element bound (∝ h_min).
      const double ratio = model.stable_time_step_s / fair_model.stable_time_step_s;
      run.check("stable step / the fair mesh's, at most the bound from P's Rayleigh quotient",
                ratio,
                step_for(model, rayleigh_lower_bound(mesh, model, kPushed)) /
                    fair_model.stable_time_step_s);
      run.check("stable step / the fair mesh's, at least the element-by-element bound", ratio,
                step_for(model, element_upper_bound(mesh)) / fair_model.stable_time_step_s, false);
    }
    for (int k = 1; k <= kRampIntervals; ++k)
      run.advance({scaled(loads, static_cast<double>(k) / kRampIntervals), {}}, kRampInterval);
    run.advance({loads, {}}, 0.01, static_cast<int>(std::lround(kHold / 0.01)));
    const double held = stretch_of(mesh, run.state.position_m);
    run.check("|stretch − exact homogeneous stretch| / (exact − 1), held",
              std::abs(held - exact) / (exact - 1.0), transient);

    const double released = run.held_j();
    double largest = released;
    for (int i = 0; i < static_cast<int>(std::lround(kFree / 0.01)) && run.advance({}, 0.01); ++i)
      largest = std::max(largest, run.held_j());
    run.check("largest held energy while free / at release", largest / released, 1.0 + 1e-6);
    run.check("|stretch − 1| after release / (exact − 1)",
              std::abs(stretch_of(mesh, run.state.position_m) - 1.0) / (exact - 1.0),
              2.0 * std::exp(-0.5 * kDamping * kFree));
    if (!is_explicit(kind))
      run.check("unconverged implicit steps", run.result().steps.unconverged_steps, 0.0);
    run.check("rollbacks", run.result().rollbacks, 0.0);
    runs.push_back(run.finish(kLength, kEnergyTolerance));
  }
  runs.push_back(zero_volume_run());
  return runs;
}

}  // namespace liversim::detail
