#include "render/scenario_overlay.h"

#include <vtkActor.h>
#include <vtkConeSource.h>
#include <vtkLineSource.h>
#include <vtkPlaneSource.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>
#include <vtkTubeFilter.h>

#include <Eigen/Geometry>

namespace liversim {
namespace {

// The lesion being edited: brighter than the others (kLesionColour).
constexpr double kSelectedLesionColour[3] = {1.0, 0.95, 0.35};
constexpr double kFixedColour[3] = {0.25, 0.5, 0.95};
constexpr double kPlaneColour[3] = {0.2, 0.85, 0.4};
constexpr double kFibreColour[3] = {1.0, 0.55, 0.1};

vtkSmartPointer<vtkActor> make_actor(vtkAlgorithmOutput* output, const double colour[3],
                                     double opacity) {
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  mapper->SetInputConnection(output);
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(colour[0], colour[1], colour[2]);
  actor->GetProperty()->SetOpacity(opacity);
  actor->PickableOff();  // picks go to the organ: the editor finds markers by their own shapes
  actor->VisibilityOff();
  return actor;
}

}  // namespace

ScenarioOverlay::ScenarioOverlay(vtkRenderer* renderer) : renderer_(renderer) {
  vtkNew<vtkSphereSource> sphere;
  sphere->SetRadius(1.0);
  sphere->SetThetaResolution(32);
  sphere->SetPhiResolution(20);
  unit_sphere_ = vtkSmartPointer<vtkPolyDataMapper>::New();
  unit_sphere_->SetInputConnection(sphere->GetOutputPort());

  plane_ = vtkSmartPointer<vtkPlaneSource>::New();
  plane_actor_ = make_actor(plane_->GetOutputPort(), kPlaneColour, 0.45);
  plane_actor_->GetProperty()->BackfaceCullingOff();
  renderer_->AddActor(plane_actor_);

  arrow_shaft_ = vtkSmartPointer<vtkLineSource>::New();
  vtkNew<vtkTubeFilter> tube;
  tube->SetInputConnection(arrow_shaft_->GetOutputPort());
  tube->SetRadius(0.0015);
  tube->SetNumberOfSides(12);
  arrow_shaft_actor_ = make_actor(tube->GetOutputPort(), kFibreColour, 1.0);
  arrow_head_ = vtkSmartPointer<vtkConeSource>::New();
  arrow_head_->SetResolution(20);
  arrow_head_actor_ = make_actor(arrow_head_->GetOutputPort(), kFibreColour, 1.0);
  renderer_->AddActor(arrow_shaft_actor_);
  renderer_->AddActor(arrow_head_actor_);
}

ScenarioOverlay::~ScenarioOverlay() {
  for (auto* pool : {&lesions_, &fixed_balls_})
    for (auto& actor : *pool) renderer_->RemoveActor(actor);
  for (vtkActor* actor : {plane_actor_.Get(), arrow_shaft_actor_.Get(), arrow_head_actor_.Get()})
    renderer_->RemoveActor(actor);
}

vtkActor* ScenarioOverlay::ball(std::vector<vtkSmartPointer<vtkActor>>& pool, std::size_t i) {
  while (pool.size() <= i) {
    auto actor = vtkSmartPointer<vtkActor>::New();
    actor->SetMapper(unit_sphere_);
    actor->PickableOff();
    renderer_->AddActor(actor);
    pool.push_back(actor);
  }
  return pool[i];
}

void ScenarioOverlay::show_lesions(const std::vector<LesionMarker>& lesions) {
  for (std::size_t i = 0; i < lesions.size(); ++i) {
    vtkActor* actor = ball(lesions_, i);
    const LesionMarker& l = lesions[i];
    actor->SetPosition(l.centre_m.x(), l.centre_m.y(), l.centre_m.z());
    actor->SetScale(l.radii_m.x(), l.radii_m.y(), l.radii_m.z());
    const double* colour = l.selected ? kSelectedLesionColour : kLesionColour;
    vtkProperty* p = actor->GetProperty();
    p->SetColor(colour[0], colour[1], colour[2]);
    p->SetSpecular(0.3);
    p->SetInterpolationToPhong();
    actor->VisibilityOn();
  }
  for (std::size_t i = lesions.size(); i < lesions_.size(); ++i) lesions_[i]->VisibilityOff();
  lesion_count_ = lesions.size();
}

void ScenarioOverlay::show_fixed_balls(
    const std::vector<std::pair<Eigen::Vector3d, double>>& balls_m) {
  for (std::size_t i = 0; i < balls_m.size(); ++i) {
    vtkActor* actor = ball(fixed_balls_, i);
    const auto& [centre, radius] = balls_m[i];
    actor->SetPosition(centre.x(), centre.y(), centre.z());
    actor->SetScale(radius);
    actor->GetProperty()->SetColor(kFixedColour[0], kFixedColour[1], kFixedColour[2]);
    actor->GetProperty()->SetOpacity(0.5);
    actor->VisibilityOn();
  }
  for (std::size_t i = balls_m.size(); i < fixed_balls_.size(); ++i)
    fixed_balls_[i]->VisibilityOff();
  fixed_ball_count_ = balls_m.size();
}

void ScenarioOverlay::show_plane(const std::optional<PlaneMarker>& plane) {
  plane_actor_->SetVisibility(plane.has_value());
  if (!plane) return;
  // A square in the plane: two axes perpendicular to the normal.
  const Eigen::Vector3d n = plane->normal.normalized();
  const Eigen::Vector3d helper =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = n.cross(helper).normalized() * plane->half_size_m;
  const Eigen::Vector3d v = n.cross(u).normalized() * plane->half_size_m;
  const Eigen::Vector3d origin = plane->point_m - u - v, p1 = plane->point_m + u - v,
                        p2 = plane->point_m - u + v;
  plane_->SetOrigin(origin.x(), origin.y(), origin.z());
  plane_->SetPoint1(p1.x(), p1.y(), p1.z());
  plane_->SetPoint2(p2.x(), p2.y(), p2.z());
}

void ScenarioOverlay::show_fibre_direction(const std::optional<ArrowMarker>& arrow) {
  arrow_shaft_actor_->SetVisibility(arrow.has_value());
  arrow_head_actor_->SetVisibility(arrow.has_value());
  if (!arrow) return;
  const Eigen::Vector3d d = arrow->direction.normalized();
  const double head_m = 0.2 * arrow->length_m;
  const Eigen::Vector3d shaft_end = arrow->from_m + d * (arrow->length_m - head_m);
  arrow_shaft_->SetPoint1(arrow->from_m.data());
  arrow_shaft_->SetPoint2(shaft_end.data());
  const Eigen::Vector3d head_centre = shaft_end + d * (0.5 * head_m);
  arrow_head_->SetCenter(head_centre.data());
  arrow_head_->SetDirection(d.data());
  arrow_head_->SetHeight(head_m);
  arrow_head_->SetRadius(0.4 * head_m);
}

std::size_t ScenarioOverlay::shown_lesion_count() const {
  return lesion_count_;
}
std::size_t ScenarioOverlay::shown_fixed_ball_count() const {
  return fixed_ball_count_;
}

}  // namespace liversim
