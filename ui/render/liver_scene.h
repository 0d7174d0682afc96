#pragma once
// The VTK scene of the liver: a smooth-shaded surface updated from simulation snapshots, picking,
// and conversion between the screen and the scene. VTK only (no Qt): the workstation, the CLI and
// the rendering tests share it.

#include "liversim/core/model.h"
#include "liversim/core/surface.h"
#include "liversim/core/tet_mesh.h"
#include "liversim/core/tools.h"

#include <vtkNew.h>
#include <vtkSmartPointer.h>
#include <Eigen/Core>

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <vector>

class vtkActor;
class vtkCellPicker;
class vtkFloatArray;
class vtkPoints;
class vtkPolyData;
class vtkRenderer;
class vtkLineSource;
class vtkSphereSource;
class vtkTubeFilter;
class vtkUnsignedCharArray;

namespace liversim {

struct ScenePick {
  Eigen::Vector3d point_m;  // where the ray hit the liver surface
  NodeIndex nearest_node;   // nearest mesh node of the hit triangle
};

class LiverScene {
 public:
  // Shows `visual` (its rest shape when given the mesh's rest positions).
  LiverScene(const TetMesh& mesh, VisualSurface visual);
  ~LiverScene();
  LiverScene(const LiverScene&) = delete;
  LiverScene& operator=(const LiverScene&) = delete;

  vtkRenderer* renderer() const;
  const BoundarySurface& surface() const { return visual_.surface; }

  // Shows another surface (the mesh changed: a cut), at these node positions; faces flagged in
  // `cut_faces` (one per triangle; empty: none) in the colour of the organ's interior.
  void set_surface(VisualSurface visual, const std::vector<std::uint8_t>& cut_faces,
                   const NodeArray& position_m);
  // Shows a cut model's boundary at these positions, its cut faces in the interior colour. A node
  // still where a node of the organ's first surface was (the same node, or its copy) keeps that
  // node's smooth visual vertex; the others show where they are.
  void show_cut_model(const SimModel& model, const NodeArray& position_m);
  // Shows the organ's first surface again (the scene restarted from rest).
  void show_uncut(const NodeArray& position_m);
  // Moves the surface to these node positions (all mesh nodes). Allocates nothing after the first.
  void update_positions(const NodeArray& position_m);
  // Anterior view of the whole organ, in a view `aspect` (width / height) wide: a view narrower
  // than tall backs off so that the organ fits across it too.
  void reset_camera(double aspect = 1.0);
  // See-through: the organ at `opacity` (< 1), front faces only, so what lies inside it (lesions:
  // scenario_overlay.h) shows through one clean layer; 1 is solid.
  void set_opacity(double opacity);
  double opacity() const;
  // A small sphere at the grabbed point, or none.
  void show_grab_marker(const std::optional<Eigen::Vector3d>& point_m);
  // The tool's parts (tools.h: tool_capsules) as steel-grey rods with rounded ends; none hides it.
  void show_tool(std::span<const Capsule> parts);
  void show_tool(const std::optional<Tool>& tool);  // its parts (tool_capsules), or none

  // Display coordinates are VTK's: pixels from the bottom-left corner of the render window.
  std::optional<ScenePick> pick(int display_x, int display_y) const;
  // The point under the display position on the plane through `on_plane_m` facing the camera.
  Eigen::Vector3d display_to_world(int display_x, int display_y,
                                   const Eigen::Vector3d& on_plane_m) const;
  Eigen::Vector2d world_to_display(const Eigen::Vector3d& point_m) const;

 private:
  VisualSurface visual_;
  const VisualSurface uncut_visual_;
  // The smooth visual vertex of each node of the first surface, by the node's rest position.
  std::map<std::array<double, 3>, Eigen::Vector3d> smooth_vertex_at_;
  vtkNew<vtkRenderer> renderer_;
  vtkNew<vtkPoints> points_;
  vtkNew<vtkFloatArray> normals_;
  vtkNew<vtkUnsignedCharArray> face_colours_;
  vtkNew<vtkPolyData> polydata_;
  vtkNew<vtkActor> liver_actor_;
  vtkNew<vtkActor> grab_marker_;
  vtkNew<vtkCellPicker> picker_;
  // One rod per tool part: a tube along the segment and spheres on its ends.
  struct ToolPart {
    vtkSmartPointer<vtkLineSource> line;
    vtkSmartPointer<vtkTubeFilter> tube;
    std::array<vtkSmartPointer<vtkSphereSource>, 2> end;
    std::array<vtkSmartPointer<vtkActor>, 3> actors;  // tube, two ends
  };
  std::array<ToolPart, 3> tool_parts_;
  std::vector<double> vertex_xyz_;
  std::vector<float> normal_scratch_;
};

// Renders the scene offscreen at the given size and writes a PNG. Needs an X display (Debian's VTK
// has no EGL or OSMesa): under no display, run it inside xvfb-run. Throws std::runtime_error naming
// the problem when there is no display or the file cannot be written (no partial file is left).
// The scene's renderer is borrowed for the render, so the scene must not be on screen elsewhere.
void write_screenshot_png(LiverScene& scene, const std::filesystem::path& file, int width,
                          int height);

}  // namespace liversim
