// The simulation's gradable metrics (issue 10, docs/session-metrics.md): tissue damage, resected
// volume, lesion margin and breach, deviation from the planned plane, task success. Each against
// an answer worked out by hand, on synthetic geometry or a block cut by the real cutter.
#include "block_mesh.h"

#include "liversim/engine/model_building.h"
#include "liversim/sessions/outcome_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace liversim {
namespace {

using Triangle = std::array<Eigen::Vector3d, 3>;

Ellipsoid ellipsoid(Eigen::Vector3d centre, Eigen::Vector3d radii) {
  return Ellipsoid{centre, radii};
}

TEST(OutcomeGeometry, DistanceToASphereIsTheDistanceToItsCentreLessTheRadius) {
  const Ellipsoid ball = ellipsoid({0.01, -0.02, 0.03}, {0.005, 0.005, 0.005});
  const Eigen::Vector3d direction = Eigen::Vector3d(1.0, 2.0, -2.0).normalized();
  for (double d : {1e-4, 3e-3, 0.2})
    EXPECT_NEAR(distance_to_ellipsoid_m(ball.centre_m + (0.005 + d) * direction, ball), d, 1e-15);
  EXPECT_EQ(distance_to_ellipsoid_m(ball.centre_m + 0.004 * direction, ball), 0.0);  // inside
  EXPECT_EQ(distance_to_ellipsoid_m(ball.centre_m, ball), 0.0);
}

TEST(OutcomeGeometry, DistanceToAnEllipsoidIsItsSurfacesNearestPoint) {
  const Ellipsoid e = ellipsoid({0.0, 0.0, 0.0}, {0.03, 0.01, 0.02});
  // On an axis the nearest point is the axis' end.
  EXPECT_NEAR(distance_to_ellipsoid_m({0.05, 0.0, 0.0}, e), 0.02, 1e-15);
  EXPECT_NEAR(distance_to_ellipsoid_m({0.0, -0.015, 0.0}, e), 0.005, 1e-15);
  // Off the axes, against the least distance to a dense grid of surface points (θ, φ in steps of
  // h): that least is at least the exact distance and at most the exact plus the largest gap
  // between neighbouring grid points, which is below r_max·h·√2.
  const int steps = 720;
  const double h = std::numbers::pi / steps;
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.04, 0.02, 0.01), Eigen::Vector3d(-0.01, 0.012, -0.03),
        Eigen::Vector3d(0.02, -0.005, 0.018)}) {
    double least = INFINITY;
    for (int i = 0; i <= steps; ++i)
      for (int j = 0; j < 2 * steps; ++j) {
        const double theta = i * h, phi = j * h;
        const Eigen::Vector3d s(0.03 * std::sin(theta) * std::cos(phi),
                                0.01 * std::sin(theta) * std::sin(phi), 0.02 * std::cos(theta));
        least = std::min(least, (p - s).norm());
      }
    const double d = distance_to_ellipsoid_m(p, e);
    EXPECT_LE(d, least + 1e-15);
    EXPECT_GE(d, least - 0.03 * h * std::sqrt(2.0));
  }
}

TEST(OutcomeGeometry, ATriangleMeetsABallThroughItsInteriorOrAnEdgeNotJustItsCorners) {
  const Ellipsoid ball = ellipsoid({0.0, 0.0, 0.0}, {0.01, 0.01, 0.01});
  // A large triangle in the plane z = 0.009: every corner is far outside, its middle is inside.
  const Triangle big{Eigen::Vector3d(-0.1, -0.1, 0.009), Eigen::Vector3d(0.1, -0.1, 0.009),
                     Eigen::Vector3d(0.0, 0.1, 0.009)};
  EXPECT_TRUE(triangle_meets_ellipsoid(big, ball));
  Triangle above = big;
  for (auto& corner : above) corner.z() = 0.0101;
  EXPECT_FALSE(triangle_meets_ellipsoid(above, ball));
  // An edge passing 9 mm from the centre, the rest of the triangle farther.
  const Triangle edge{Eigen::Vector3d(-0.1, 0.009, 0.0), Eigen::Vector3d(0.1, 0.009, 0.0),
                      Eigen::Vector3d(0.0, 0.1, 0.0)};
  EXPECT_TRUE(triangle_meets_ellipsoid(edge, ball));
  // Scaled by the radii: a flat ellipsoid 2 mm thick is missed by a plane 1.1 mm above it.
  const Ellipsoid flat = ellipsoid({0.0, 0.0, 0.0}, {0.05, 0.05, 0.001});
  Triangle over = big;
  for (auto& corner : over) corner.z() = 0.0011;
  EXPECT_FALSE(triangle_meets_ellipsoid(over, flat));
  for (auto& corner : over) corner.z() = 0.0009;
  EXPECT_TRUE(triangle_meets_ellipsoid(over, flat));
}

TEST(OutcomeGeometry, DamageIsAPrincipalStretchBeyondTheTensionOrCompressionStrain) {
  const double tension = 0.3, compression = 0.5;
  auto damaged = [&](const Eigen::Matrix3d& f) { return strained_beyond(f, tension, compression); };
  EXPECT_FALSE(damaged(Eigen::Matrix3d::Identity()));
  EXPECT_FALSE(damaged(Eigen::Vector3d(1.29, 1.0, 1.0).asDiagonal()));
  EXPECT_TRUE(damaged(Eigen::Vector3d(1.31, 1.0, 1.0).asDiagonal()));
  EXPECT_FALSE(damaged(Eigen::Vector3d(1.0, 0.51, 1.0).asDiagonal()));
  EXPECT_TRUE(damaged(Eigen::Vector3d(1.0, 1.0, 0.49).asDiagonal()));
  // A rotation changes no stretch.
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  EXPECT_FALSE(damaged(rotation * Eigen::Vector3d(1.29, 0.52, 1.0).asDiagonal()));
  EXPECT_TRUE(damaged(rotation * Eigen::Vector3d(1.29, 0.48, 1.0).asDiagonal()));
  // Simple shear γ: the largest principal stretch is γ/2 + √(1 + γ²/4), 1.3 at γ = 1.3 − 1/1.3
  // (the smallest is its inverse, 0.77: no crushing).
  const double gamma = 1.3 - 1.0 / 1.3;
  for (double g : {gamma * 0.99, gamma * 1.01}) {
    Eigen::Matrix3d shear = Eigen::Matrix3d::Identity();
    shear(0, 1) = g;
    EXPECT_EQ(damaged(shear), g > gamma) << "γ = " << g;
  }
}

TEST(OutcomeGeometry, MeanPlaneDistanceIntegratesTheAbsoluteDistanceOverEachTriangle) {
  PlaneSpec plane;
  plane.point_mm = {0.0, 0.0, 10.0};
  plane.normal = {0.0, 0.0, 2.0};                       // not normalised: the function normalises
  auto at_heights = [](double a, double b, double c) {  // corners' heights above z = 10 mm (mm)
    return Triangle{Eigen::Vector3d(0.0, 0.0, 0.010 + a * 1e-3),
                    Eigen::Vector3d(0.02, 0.0, 0.010 + b * 1e-3),
                    Eigen::Vector3d(0.0, 0.03, 0.010 + c * 1e-3)};
  };
  // One side: the mean of the corners' distances.
  std::vector<Triangle> one{at_heights(1.0, 2.0, 3.0)};
  EXPECT_NEAR(*mean_plane_distance_m(one, plane), 2e-3, 1e-15);
  // Corners at +1, −1, 0 mm: the zero line halves the triangle into two with corner values
  // (±1, 0, 0), each of mean 1/3 mm.
  std::vector<Triangle> split{at_heights(1.0, -1.0, 0.0)};
  // The tilt makes the triangle's area differ from its projection, not the mean.
  EXPECT_NEAR(*mean_plane_distance_m(split, plane), 1e-3 / 3.0, 1e-15);
  // Corners at +2, −1, −1 mm: the zero line cuts off the +2 corner with 2/3 of each edge, a
  // triangle of 4/9 of the area where d averages 2/3 mm (∫d = 8/27 A); ∫d over the whole is 0,
  // so ∫|d| = 16/27 A.
  std::vector<Triangle> corner{at_heights(2.0, -1.0, -1.0)};
  EXPECT_NEAR(*mean_plane_distance_m(corner, plane), 16e-3 / 27.0, 1e-15);
  // Area-weighted: a triangle of twice the area at 4 mm with one of 1 at 1 mm gives 3 mm.
  Triangle twice = at_heights(4.0, 4.0, 4.0);
  twice[1].x() = 0.04;
  std::vector<Triangle> both{at_heights(1.0, 1.0, 1.0), twice};
  EXPECT_NEAR(*mean_plane_distance_m(both, plane), 3e-3, 1e-15);
  EXPECT_FALSE(mean_plane_distance_m({}, plane));
}

TEST(OutcomeGeometry, LesionMarginIsTheLeastDistanceWithinTheSampleSpacing) {
  const Ellipsoid ball = ellipsoid({0.0, 0.0, 0.0}, {0.005, 0.005, 0.005});
  // A 10 cm square in the plane z = 0.013, made of two triangles whose corners are far from the
  // ball: the margin, 8 mm, is at the square's interior point above the centre.
  auto square_at = [](double z) {
    const Eigen::Vector3d a(-0.05, -0.047, z), b(0.05, -0.047, z), c(0.05, 0.053, z),
        d(-0.05, 0.053, z);
    return std::vector<Triangle>{{a, b, c}, {a, c, d}};
  };
  const double spacing = 0.5e-3;
  const std::optional<LesionMargin> margin = lesion_margin(square_at(0.013), ball, spacing);
  ASSERT_TRUE(margin);
  EXPECT_FALSE(margin->breached);
  EXPECT_GE(margin->margin_m, 0.008 - 1e-15);
  EXPECT_LE(margin->margin_m, 0.008 + spacing);
  const std::optional<LesionMargin> through = lesion_margin(square_at(0.004), ball, spacing);
  ASSERT_TRUE(through);
  EXPECT_TRUE(through->breached);
  EXPECT_EQ(through->margin_m, 0.0);
  EXPECT_FALSE(lesion_margin({}, ball, spacing));
}

// ---- On a block cut by the real cutter ---------------------------------------------------------

// Block [0, 0.06] × [0, 0.05] × [0, 0.04] m of 1 cm cubes, fixed at its base; the cube
// [0.02, 0.03] × [0.02, 0.03] × [0.03, 0.04] is region 1 (the lesion's tissue).
struct Block {
  SimModel model;
  SimState state;
};
Block lesion_block() {
  TetMesh mesh = testing::block_mesh(6, 5, 4, {0.06, 0.05, 0.04});
  ModelOptions options;
  options.regions.push_back(RegionMaterial{});
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (NodeIndex n : mesh.tet(e)) centroid += mesh.rest_position_m.at(n) / 4.0;
    if (centroid.x() > 0.02 && centroid.x() < 0.03 && centroid.y() > 0.02 && centroid.y() < 0.03 &&
        centroid.z() > 0.03)
      mesh.region[e] = 1;
  }
  for (std::size_t n = 0; n < mesh.node_count(); ++n)
    if (mesh.rest_position_m.z[n] < 1e-9) options.fixed_nodes.push_back(static_cast<NodeIndex>(n));
  SimModel model = build_model(mesh, options);
  SimState state = make_rest_state(model);
  return {std::move(model), std::move(state)};
}

// The top of the block off: a horizontal sweep at z = 0.032 (nodes at z = 0.03 snap onto it).
CutResult cut_top_off(const Block& block) {
  const double z = 0.032;
  BladeStroke stroke;
  stroke.add({Eigen::Vector3d(-0.01, -0.01, z), Eigen::Vector3d(-0.01, 0.06, z)});
  stroke.add({Eigen::Vector3d(0.07, -0.01, z), Eigen::Vector3d(0.07, 0.06, z)});
  CuttingSettings settings;
  settings.cutting_stress_pa = 0.0;
  return cut_tissue(block.model, block.state, stroke, settings);
}

Scenario resection(double lesion_radius_mm, double margin_mm) {
  Scenario scenario;
  LesionSpec lesion;
  lesion.name = "tumour";
  lesion.centre_mm = {25.0, 25.0, 37.0};
  lesion.radii_mm = {lesion_radius_mm, lesion_radius_mm, lesion_radius_mm};
  scenario.lesions.push_back(lesion);
  scenario.task.kind = TaskKind::resect_lesion;
  scenario.task.lesion = "tumour";
  scenario.task.margin_mm = margin_mm;
  scenario.task.planned_plane = PlaneSpec{{0.0, 0.0, 30.0}, {0.0, 0.0, 1.0}};
  return scenario;
}

// A tracker that has followed the block through the cut (nothing taken out).
OutcomeTracker tracker_before_take_out(const Block& block, const CutResult& cut) {
  OutcomeTracker tracker(block.model, std::nullopt);
  tracker.carry_over(cut);
  return tracker;
}

double metric(const std::vector<MetricValue>& values, const std::string& name) {
  for (const MetricValue& v : values)
    if (v.name == name) return v.value;
  ADD_FAILURE() << "no metric " << name;
  return NAN;
}
bool has_metric(const std::vector<MetricValue>& values, const std::string& name) {
  for (const MetricValue& v : values)
    if (v.name == name) return true;
  return false;
}

TEST(OutcomeMetrics, ResectingTheTopOfABlockMeasuresMarginPlaneVolumeAndSuccess) {
  const Block block = lesion_block();
  OutcomeTracker tracker(block.model, std::nullopt);
  tracker.observe(block.model, block.state.position_m);
  const CutResult cut = cut_top_off(block);
  ASSERT_TRUE(cut.cut());
  tracker.carry_over(cut);
  // The cut faces lie on z = 32 mm (snapped); the lesion ball of 2 mm around z = 37 mm is 3 mm
  // above them; the planned plane z = 30 mm is 2 mm below them everywhere.
  const double spacing_mm = OutcomeSettings{}.margin_sample_spacing_mm;
  const Scenario wide = resection(2.0, 2.5);
  OutcomeMetrics m = compute_outcome_metrics(block.model, *cut.model, tracker, &wide, {});
  ASSERT_EQ(m.lesions.size(), 1u);
  ASSERT_TRUE(m.lesions[0].margin);
  EXPECT_FALSE(m.lesions[0].margin->breached);
  EXPECT_GE(m.lesions[0].margin->margin_m * 1e3, 3.0 - 1e-9);
  EXPECT_LE(m.lesions[0].margin->margin_m * 1e3, 3.0 + spacing_mm);
  EXPECT_TRUE(m.lesions[0].removed);  // the lesion's cube went with the top
  ASSERT_TRUE(m.plane_deviation_mm);
  EXPECT_NEAR(*m.plane_deviation_mm, 2.0, 1e-9);
  const double top_mm3 = 60.0 * 50.0 * 8.0;
  EXPECT_NEAR(m.resected_volume_mm3, top_mm3, 1e-9 * top_mm3);
  EXPECT_EQ(m.task_success, std::optional<bool>(true));
  const std::vector<MetricValue> values = outcome_metric_values(m, &wide);
  EXPECT_EQ(metric(values, "task_success"), 1.0);
  EXPECT_EQ(metric(values, "lesion_breached"), 0.0);
  EXPECT_EQ(metric(values, "lesion_margin_mm"), metric(values, "lesion_margin_mm:tumour"));
  EXPECT_NEAR(metric(values, "plane_deviation_mm"), 2.0, 1e-9);

  // The same cut against a 4 mm margin: too close, so no success.
  const Scenario narrow = resection(2.0, 4.0);
  m = compute_outcome_metrics(block.model, *cut.model, tracker, &narrow, {});
  EXPECT_EQ(m.task_success, std::optional<bool>(false));
  // A lesion of 6 mm reaches below z = 32 mm: the cut went through it.
  const Scenario big = resection(6.0, 1.0);
  m = compute_outcome_metrics(block.model, *cut.model, tracker, &big, {});
  EXPECT_TRUE(m.lesions[0].margin->breached);
  EXPECT_EQ(m.task_success, std::optional<bool>(false));
  EXPECT_EQ(metric(outcome_metric_values(m, &big), "lesion_breached"), 1.0);
}

// Issue 42: the top the cut freed stays as a body, the specimen. Worked out by hand: its volume is
// the top's, 60 × 50 × 8 mm; the lesion's elements (the cell over x, y in 20–30 mm, z in 30–40 mm)
// are all in it; its cut faces lie on z = 32 mm, 3 mm below the 2 mm ball around z = 37 mm.
TEST(OutcomeMetrics, TheSpecimenHoldsTheLesionWithItsMarginAndIsR0WhenTheMarginSuffices) {
  const Block block = lesion_block();
  OutcomeTracker tracker(block.model, std::nullopt);
  const CutResult cut = cut_top_off(block);
  ASSERT_TRUE(cut.cut());
  tracker.carry_over(cut);
  const double spacing_mm = OutcomeSettings{}.margin_sample_spacing_mm;
  const double top_mm3 = 60.0 * 50.0 * 8.0;
  const Scenario wide = resection(2.0, 2.5);
  OutcomeMetrics m = compute_outcome_metrics(block.model, *cut.model, tracker, &wide, {});
  ASSERT_EQ(m.specimens.size(), 1u);
  EXPECT_FALSE(m.specimens[0].taken_out);  // still in the field
  EXPECT_NEAR(m.specimens[0].volume_mm3, top_mm3, 1e-9 * top_mm3);
  ASSERT_EQ(m.specimens[0].lesions.size(), 1u);
  EXPECT_TRUE(m.specimens[0].lesions[0].whole);
  ASSERT_TRUE(m.specimens[0].lesions[0].margin);
  EXPECT_FALSE(m.specimens[0].lesions[0].margin->breached);
  std::vector<MetricValue> values = outcome_metric_values(m, &wide);
  EXPECT_NEAR(metric(values, "specimen_volume_mm3"), top_mm3, 1e-9 * top_mm3);
  EXPECT_EQ(metric(values, "specimen_contains_lesion"), 1.0);
  EXPECT_GE(metric(values, "specimen_margin_mm"), 3.0 - 1e-9);
  EXPECT_LE(metric(values, "specimen_margin_mm"), 3.0 + spacing_mm);
  EXPECT_EQ(metric(values, "specimen_margin_mm:tumour"), metric(values, "specimen_margin_mm"));
  EXPECT_EQ(metric(values, "specimen_r0"), 1.0);
  EXPECT_TRUE(m.lesions[0].removed);  // out of the organ, in the specimen
  EXPECT_EQ(m.task_success, std::optional<bool>(true));

  // Taken out of the field, the specimen is measured the same.
  const std::vector<FreeBody> bodies = free_bodies(*cut.model);
  ASSERT_EQ(bodies.size(), 1u);
  const CutResult removal = take_out_body(*cut.model, cut.state, bodies[0].elements.front());
  tracker.take_out(*cut.model, bodies[0].elements, removal);
  ASSERT_EQ(tracker.specimens_taken_out().size(), 1u);
  const OutcomeMetrics out =
      compute_outcome_metrics(block.model, *removal.model, tracker, &wide, {});
  ASSERT_EQ(out.specimens.size(), 1u);
  EXPECT_TRUE(out.specimens[0].taken_out);
  EXPECT_NEAR(out.specimens[0].volume_mm3, top_mm3, 1e-9 * top_mm3);
  const std::vector<MetricValue> out_values = outcome_metric_values(out, &wide);
  EXPECT_EQ(metric(out_values, "specimen_margin_mm"), metric(values, "specimen_margin_mm"));
  EXPECT_EQ(metric(out_values, "specimen_r0"), 1.0);
  EXPECT_EQ(metric(out_values, "resected_volume_mm3"), metric(values, "resected_volume_mm3"));

  // Against a 4 mm margin the same specimen is not R0; a 6 mm lesion reaches through the cut faces.
  const Scenario narrow = resection(2.0, 4.0);
  values = outcome_metric_values(
      compute_outcome_metrics(block.model, *cut.model, tracker_before_take_out(block, cut), &narrow,
                              {}),
      &narrow);
  EXPECT_EQ(metric(values, "specimen_contains_lesion"), 1.0);
  EXPECT_EQ(metric(values, "specimen_r0"), 0.0);
  const Scenario big = resection(6.0, 1.0);
  values =
      outcome_metric_values(compute_outcome_metrics(block.model, *cut.model,
                                                    tracker_before_take_out(block, cut), &big, {}),
                            &big);
  EXPECT_EQ(metric(values, "specimen_margin_mm"), 0.0);
  EXPECT_EQ(metric(values, "specimen_r0"), 0.0);
}

// A cut under the lesion's cell leaves part of it in the organ: the specimen does not hold the
// lesion, it has no specimen margin, and R0 fails.
TEST(OutcomeMetrics, ASpecimenHoldingPartOfTheLesionDoesNotContainIt) {
  Block block = lesion_block();
  for (std::size_t e = 0; e < block.model.tet_count; ++e) {  // the lesion's column down to 20 mm
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int c = 0; c < 4; ++c)
      centroid += block.model.rest_position_m.at(block.model.corner[c][e]) / 4.0;
    if (centroid.x() > 0.02 && centroid.x() < 0.03 && centroid.y() > 0.02 && centroid.y() < 0.03 &&
        centroid.z() > 0.02)
      block.model.region[e] = 1;
  }
  OutcomeTracker tracker(block.model, std::nullopt);
  const CutResult cut = cut_top_off(block);
  ASSERT_TRUE(cut.cut());
  tracker.carry_over(cut);
  const Scenario scenario = resection(2.0, 1.0);
  const OutcomeMetrics m = compute_outcome_metrics(block.model, *cut.model, tracker, &scenario, {});
  ASSERT_EQ(m.specimens.size(), 1u);
  ASSERT_EQ(m.specimens[0].lesions.size(), 1u);
  EXPECT_FALSE(m.specimens[0].lesions[0].whole);
  EXPECT_FALSE(m.lesions[0].removed);
  const std::vector<MetricValue> values = outcome_metric_values(m, &scenario);
  EXPECT_EQ(metric(values, "specimen_contains_lesion"), 0.0);
  EXPECT_FALSE(has_metric(values, "specimen_margin_mm"));
  EXPECT_EQ(metric(values, "specimen_r0"), 0.0);
}

TEST(OutcomeMetrics, BeforeAnyCutThereIsNoMarginNorPlaneDeviationAndTheLesionIsNotRemoved) {
  const Block block = lesion_block();
  OutcomeTracker tracker(block.model, std::nullopt);
  const Scenario scenario = resection(2.0, 1.0);
  const OutcomeMetrics m =
      compute_outcome_metrics(block.model, block.model, tracker, &scenario, {});
  EXPECT_FALSE(m.lesions[0].margin);
  EXPECT_FALSE(m.lesions[0].removed);
  EXPECT_FALSE(m.plane_deviation_mm);
  EXPECT_EQ(m.task_success, std::optional<bool>(false));
  const std::vector<MetricValue> values = outcome_metric_values(m, &scenario);
  EXPECT_FALSE(has_metric(values, "lesion_margin_mm"));
  EXPECT_FALSE(has_metric(values, "plane_deviation_mm"));
  EXPECT_EQ(metric(values, "resected_volume_mm3"), 0.0);
  EXPECT_FALSE(has_metric(values, "specimen_volume_mm3"));
  EXPECT_EQ(metric(values, "specimen_contains_lesion"), 0.0);
  EXPECT_EQ(metric(values, "specimen_r0"), 0.0);
  // Free practice: no scenario, no task.
  const OutcomeMetrics free =
      compute_outcome_metrics(block.model, block.model, tracker, nullptr, {});
  EXPECT_FALSE(free.task_success);
  EXPECT_FALSE(has_metric(outcome_metric_values(free, nullptr), "task_success"));
}

TEST(OutcomeMetrics, DamageIsTheVolumeEverStretchedPastTheDamageStrainAndFollowsCuts) {
  const Block block = lesion_block();
  OutcomeTracker tracker(block.model, std::nullopt);
  // Stretch the part above z = 0.02 by 1.4 along z (the part below stays): the elements above are
  // stretched 1.4 > 1.3, those below not at all; no element straddles z = 0.02 (a grid plane).
  NodeArray stretched = block.state.position_m;
  for (std::size_t n = 0; n < block.model.node_count; ++n)
    if (stretched.z[n] > 0.02) stretched.z[n] = 0.02 + 1.4 * (stretched.z[n] - 0.02);
  tracker.observe(block.model, stretched);
  const double upper_m3 = 0.06 * 0.05 * 0.02;
  EXPECT_NEAR(tracker.damaged_volume_m3(block.model), upper_m3, 1e-12 * upper_m3);
  // Released, it stays damaged.
  tracker.observe(block.model, block.state.position_m);
  EXPECT_NEAR(tracker.damaged_volume_m3(block.model), upper_m3, 1e-12 * upper_m3);
  // The top 8 mm cut off: only the damaged tissue left in the organ counts.
  const CutResult cut = cut_top_off(block);
  ASSERT_TRUE(cut.cut());
  tracker.carry_over(cut);
  const double left_m3 = 0.06 * 0.05 * 0.012;
  EXPECT_NEAR(tracker.damaged_volume_m3(*cut.model), left_m3, 1e-9 * left_m3);
  const OutcomeMetrics m = compute_outcome_metrics(block.model, *cut.model, tracker, nullptr, {});
  EXPECT_NEAR(m.tissue_damage_mm3, left_m3 * 1e9, 1e-9 * left_m3 * 1e9);
  // A stretch of 1.25 damages nothing.
  OutcomeTracker gentle(block.model, std::nullopt);
  NodeArray mild = block.state.position_m;
  for (std::size_t n = 0; n < block.model.node_count; ++n) mild.z[n] *= 1.25;
  gentle.observe(block.model, mild);
  EXPECT_EQ(gentle.damaged_volume_m3(block.model), 0.0);
}

TEST(OutcomeMetrics, RetractionSucceedsOnceTheGraspPointWasLiftedFarEnough) {
  const Block block = lesion_block();
  Scenario scenario;
  scenario.task.kind = TaskKind::retract_lobe;
  scenario.task.grasp_point_mm = {30.0, 20.0, 40.0};  // a node of the top face
  scenario.task.lift_mm = 30.0;
  OutcomeTracker tracker(block.model, Eigen::Vector3d(0.0301, 0.0199, 0.0401));
  NodeArray moved = block.state.position_m;
  const std::vector<NodeIndex> top =
      nodes_on_plane(testing::block_mesh(6, 5, 4, {0.06, 0.05, 0.04}), 2, 0.04);
  for (NodeIndex n : top) moved.z[n] += 0.029;  // the whole top face 29 mm up
  tracker.observe(block.model, moved);
  EXPECT_NEAR(tracker.largest_lift_m(), 0.029, 1e-15);
  EXPECT_EQ(compute_outcome_metrics(block.model, block.model, tracker, &scenario, {}).task_success,
            std::optional<bool>(false));
  for (NodeIndex n : top) moved.z[n] += 0.002;  // 31 mm
  tracker.observe(block.model, moved);
  tracker.observe(block.model, block.state.position_m);  // let go: the largest lift stays
  const OutcomeMetrics m =
      compute_outcome_metrics(block.model, block.model, tracker, &scenario, {});
  EXPECT_NEAR(m.lift_mm, 31.0, 1e-9);
  EXPECT_EQ(m.task_success, std::optional<bool>(true));
}

TEST(OutcomeMetrics, PalpationSucceedsWithAMarkOverTheLesion) {
  const Block block = lesion_block();
  Scenario scenario;
  LesionSpec lesion;
  lesion.name = "hidden";
  lesion.centre_mm = {30.0, 25.0, 25.0};
  lesion.radii_mm = {5.0, 5.0, 5.0};
  scenario.lesions.push_back(lesion);
  scenario.task.kind = TaskKind::palpate_lesion;
  scenario.task.lesion = "hidden";
  OutcomeTracker tracker(block.model, std::nullopt);
  // The lesion is 10 mm under the top face (z = 40 mm), its shallowest depth (the sides are
  // farther); with the 5 mm tolerance a mark within 15 mm of the ball locates it.
  auto success_with = [&](const Eigen::Vector3d& mark) {
    const std::vector<Eigen::Vector3d> marks{Eigen::Vector3d(0.0, 0.0, 0.0), mark};
    return *compute_outcome_metrics(block.model, block.model, tracker, &scenario, marks)
                .task_success;
  };
  EXPECT_TRUE(success_with({0.03, 0.025, 0.04}));    // straight above: 10 mm
  EXPECT_TRUE(success_with({0.042, 0.025, 0.04}));   // √(12² + 15²) − 5 = 14.2 mm
  EXPECT_FALSE(success_with({0.045, 0.025, 0.04}));  // √(15² + 15²) − 5 = 16.2 mm
  EXPECT_FALSE(*compute_outcome_metrics(block.model, block.model, tracker, &scenario, {})
                    .task_success);  // no mark
}

TEST(OutcomeMetrics, AMarkOnTheDeformedSurfaceIsCarriedBackToItsRestPoint) {
  const Block block = lesion_block();
  // The whole block moved 1 cm along y and its top pressed down 5 mm: a tip 1 mm above the
  // pressed top, over rest point (31, 22, 40) mm, marks that rest point.
  NodeArray moved = block.state.position_m;
  for (std::size_t n = 0; n < block.model.node_count; ++n) {
    moved.y[n] += 0.01;
    moved.z[n] *= 0.035 / 0.04;
  }
  const Eigen::Vector3d mark =
      rest_point_nearest(block.model, moved, Eigen::Vector3d(0.031, 0.032, 0.036));
  EXPECT_NEAR((mark - Eigen::Vector3d(0.031, 0.022, 0.04)).norm(), 0.0, 1e-12);
  const std::vector<SessionEvent> events{{1.0, SessionEventKind::lesion_marked, mark_detail(mark)},
                                         {2.0, SessionEventKind::lesion_marked, "not a point"},
                                         {3.0, SessionEventKind::grasp, "1 2 3"}};
  const std::vector<Eigen::Vector3d> marks = lesion_marks(events);
  ASSERT_EQ(marks.size(), 1u);
  EXPECT_NEAR((marks[0] - mark).norm(), 0.0, 1e-15);
}

}  // namespace
}  // namespace liversim
