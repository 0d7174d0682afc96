#pragma once
// What a scenario adds to the liver's picture in the instructor's editor: its lesions (ellipsoids
// at rest), its fixed regions (painted balls), the planned resection plane and the fibre
// direction. VTK only (no Qt), in metres like the scene. (The workstation's see-through view
// draws lesions that move with the tissue: LiverScene::show_lesions.)

#include <vtkSmartPointer.h>
#include <Eigen/Core>

#include <optional>
#include <vector>

class vtkActor;
class vtkConeSource;
class vtkLineSource;
class vtkPlaneSource;
class vtkPolyDataMapper;
class vtkRenderer;

namespace liversim {

// A tumour: pale yellow-white against the parenchyma, in the editor and the see-through view.
inline constexpr double kLesionColour[3] = {0.91, 0.80, 0.48};

struct LesionMarker {
  Eigen::Vector3d centre_m;
  Eigen::Vector3d radii_m;  // along the scene's axes
  bool selected = false;    // drawn brighter, as the one the panels edit
};

struct PlaneMarker {
  Eigen::Vector3d point_m;
  Eigen::Vector3d normal;  // unit
  double half_size_m = 0.06;
};

struct ArrowMarker {
  Eigen::Vector3d from_m;
  Eigen::Vector3d direction;  // unit
  double length_m = 0.05;
};

class ScenarioOverlay {
 public:
  // Adds its (so far hidden) actors to `renderer`, which must outlive the overlay.
  explicit ScenarioOverlay(vtkRenderer* renderer);
  ~ScenarioOverlay();
  ScenarioOverlay(const ScenarioOverlay&) = delete;
  ScenarioOverlay& operator=(const ScenarioOverlay&) = delete;

  void show_lesions(const std::vector<LesionMarker>& lesions);
  // Fixed regions: translucent blue balls (centre, radius).
  void show_fixed_balls(const std::vector<std::pair<Eigen::Vector3d, double>>& balls_m);
  void show_plane(const std::optional<PlaneMarker>& plane);
  void show_fibre_direction(const std::optional<ArrowMarker>& arrow);

  std::size_t shown_lesion_count() const;
  std::size_t shown_fixed_ball_count() const;

 private:
  // The i-th actor of a pool of unit spheres (scaled and placed), made on first use.
  vtkActor* ball(std::vector<vtkSmartPointer<vtkActor>>& pool, std::size_t i);

  vtkRenderer* renderer_;
  vtkSmartPointer<vtkPolyDataMapper> unit_sphere_;
  std::vector<vtkSmartPointer<vtkActor>> lesions_;
  std::vector<vtkSmartPointer<vtkActor>> fixed_balls_;
  std::size_t lesion_count_ = 0, fixed_ball_count_ = 0;
  vtkSmartPointer<vtkPlaneSource> plane_;
  vtkSmartPointer<vtkActor> plane_actor_;
  vtkSmartPointer<vtkLineSource> arrow_shaft_;
  vtkSmartPointer<vtkConeSource> arrow_head_;
  vtkSmartPointer<vtkActor> arrow_shaft_actor_, arrow_head_actor_;
};

}  // namespace liversim
