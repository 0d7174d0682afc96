#pragma once
// The VTK scene of the liver: a smooth-shaded surface updated from simulation snapshots, picking,
// and conversion between the screen and the scene. VTK only (no Qt): the workstation, the CLI and
// the rendering tests share it.

#include "liversim/engine/model.h"
#include "liversim/engine/surface.h"
#include "liversim/engine/tet_mesh.h"
#include "liversim/interaction/tools.h"
#include "liversim/meshing/visual_model.h"
#include "liversim/scenario/scenario.h"

#include <vtkNew.h>
#include <vtkSmartPointer.h>
#include <Eigen/Core>

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

class vtkActor;
class vtkMatrix4x4;
class vtkCellPicker;
class vtkFloatArray;
class vtkPoints;
class vtkPolyData;
class vtkRenderer;
class vtkRenderStepsPass;
class vtkSSAOPass;
class vtkLineSource;
class vtkSphereSource;
class vtkTubeFilter;
class vtkUnsignedCharArray;

namespace liversim {

// The organ's opacity in the see-through view.
inline constexpr double kSeeThroughOpacity = 0.35;

// The capsule-covered surface of the liver: a smooth mottling between a deep maroon and a lighter
// red-brown, fixed to the tissue (a function of each vertex's rest position).
inline constexpr double kTissueDarkColour[3] = {0.36, 0.09, 0.09};
inline constexpr double kTissueLightColour[3] = {0.60, 0.22, 0.14};
// Cut parenchyma: lighter and redder than the capsule-covered surface.
inline constexpr double kCutColour[3] = {0.70, 0.24, 0.20};

// A lesion as the see-through view draws it: an ellipsoid at rest, carried by the organ.
struct LesionShape {
  Eigen::Vector3d centre_m;
  Eigen::Vector3d radii_m;  // along the scene's axes
};

// The scenario's lesions a trainee may see (not the hidden ones of a palpation task).
std::vector<LesionShape> visible_lesions(const Scenario& scenario);

// The tools' models (resources/tools, read through assimp), or why they could not be read: the
// scene then draws each tool as its capsules.
struct ToolModels {
  std::optional<VisualModel> probe, forceps_body, forceps_jaw, scalpel;
  std::string problem;  // empty when all were read
};
// Reads them from `folder` (default: the shipped resources' tools folder, data_paths.h).
ToolModels load_tool_models(const std::filesystem::path& folder);
ToolModels load_tool_models();

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
  // `cut_faces` (one per triangle; empty: none) in the colour of the organ's interior, the others
  // mottled by where their vertices are at rest (`rest_position_m`, of the same nodes).
  void set_surface(VisualSurface visual, const std::vector<std::uint8_t>& cut_faces,
                   const NodeArray& rest_position_m, const NodeArray& position_m);
  // Shows a cut model's boundary at these positions, its cut faces in the interior colour. A node
  // still where a node of the organ's first surface was (the same node, or its copy) keeps that
  // node's smooth visual vertex; the others show where they are.
  void show_cut_model(const SimModel& model, const NodeArray& position_m);
  // Shows the organ's first surface again (the scene restarted from rest).
  void show_uncut(const NodeArray& position_m);
  // Lesions inside the organ (seen in the see-through view, or where a cut opens them), carried
  // by the elements that hold them at rest, and by the cut model's after a cut; the part of a
  // lesion in a piece a cut removed goes with it. None: no lesions.
  void show_lesions(const std::vector<LesionShape>& lesions);
  std::size_t shown_lesion_triangle_count() const;
  // Moves the surface to these node positions (all mesh nodes). Allocates nothing after the first.
  void update_positions(const NodeArray& position_m);
  // Anterior view of the whole organ, in a view `aspect` (width / height) wide: a view narrower
  // than tall backs off so that the organ fits across it too.
  void reset_camera(double aspect = 1.0);
  // See-through: the organ at `opacity` (< 1; kSeeThroughOpacity in the workstation and the
  // editor), front faces only, so what lies inside it (lesions) shows through one clean layer; 1
  // is solid.
  void set_opacity(double opacity);
  double opacity() const;
  // Screen-space ambient occlusion: creases, pits and the folds between lobes darkened as a diffuse
  // operating-room light would leave them; while on, the background is one colour instead of a
  // gradient (liver_scene.cpp says why). Off by default: it costs full-screen passes every frame
  // (docs/rendering-performance.md).
  void set_ambient_occlusion(bool on);
  bool ambient_occlusion() const;
  // A small sphere at the grabbed point, or none.
  void show_grab_marker(const std::optional<Eigen::Vector3d>& point_m);
  // The tool in `hand` as its parts (tools.h: tool_capsules): steel-grey rods with rounded ends;
  // none hides it. Without a hand: the right one's.
  void show_tool(Hand hand, std::span<const Capsule> parts);
  void show_tool(std::span<const Capsule> parts) { show_tool(Hand::right, parts); }
  // The tool in `hand` as its model when there is one (set_tool_models), else as its capsules;
  // none hides it. Each hand's tool is drawn apart: two hands may hold the same kind.
  void show_tool(Hand hand, const std::optional<Tool>& tool);
  void show_tool(const std::optional<Tool>& tool) { show_tool(Hand::right, tool); }
  void set_tool_models(const ToolModels& models);

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
  vtkNew<vtkUnsignedCharArray> vertex_colours_;
  std::vector<double> rest_xyz_;  // the visual vertices at rest, for their colours
  vtkNew<vtkPolyData> polydata_;
  vtkNew<vtkActor> liver_actor_;
  vtkNew<vtkActor> grab_marker_;
  vtkNew<vtkCellPicker> picker_;
  vtkNew<vtkRenderStepsPass> scene_passes_;  // VTK's usual passes, which the occlusion wraps
  vtkNew<vtkSSAOPass> occlusion_pass_;
  // One rod per tool part: a tube along the segment and spheres on its ends.
  struct ToolPart {
    vtkSmartPointer<vtkLineSource> line;
    vtkSmartPointer<vtkTubeFilter> tube;
    std::array<vtkSmartPointer<vtkSphereSource>, 2> end;
    std::array<vtkSmartPointer<vtkActor>, 3> actors;  // tube, two ends
  };
  // Tool models: one actor per model mesh, placed by the tool's pose (the forceps' jaw twice).
  struct ModelActors {
    std::vector<vtkSmartPointer<vtkActor>> actors;
    vtkNew<vtkMatrix4x4> pose;  // every actor's user matrix, updated in place
    void show(bool shown);
    void place(const Eigen::Affine3d& pose);
  };
  // What draws the tool of one hand.
  struct HandTool {
    std::array<ToolPart, 3> parts;
    std::array<ModelActors, 3> models;  // by ToolKind: probe, forceps (body), scalpel
    std::array<ModelActors, 2> forceps_jaws;
  };
  std::array<HandTool, kHands.size()> hand_tools_;
  bool has_model(ToolKind kind) const {
    return !hand_tools_[0].models[static_cast<int>(kind)].actors.empty();
  }

  // Lesions: their rest vertices and triangles, embedded in the uncut mesh and in the model shown.
  TetMesh uncut_mesh_;
  std::vector<Eigen::Vector3d> lesion_rest_m_;
  std::vector<std::array<std::int32_t, 3>> lesion_triangles_;
  EmbeddedPoints uncut_lesion_embedding_, lesion_embedding_;
  vtkNew<vtkPoints> lesion_points_;
  vtkNew<vtkFloatArray> lesion_normals_;
  vtkNew<vtkPolyData> lesion_polydata_;
  vtkNew<vtkActor> lesion_actor_;
  std::vector<double> lesion_xyz_;
  std::vector<float> lesion_normal_scratch_;
  void show_lesion_embedding(EmbeddedPoints embedding);  // its held triangles
  void update_lesion_positions(const NodeArray& position_m);
  // What is drawn: the visual vertices, then a second copy of each vertex on a cut's rim for the
  // cut faces (rim_copy_of_: the visual vertex each copies), and the triangles on them.
  std::vector<std::array<std::int32_t, 3>> drawn_triangles_;
  std::vector<std::int32_t> rim_copy_of_;
  std::vector<double> vertex_xyz_, drawn_xyz_;
  std::vector<float> normal_scratch_;
};

// Renders the scene offscreen at the given size and writes a PNG. Needs an X display (Debian's VTK
// has no EGL or OSMesa): under no display, run it inside xvfb-run. Throws std::runtime_error naming
// the problem when there is no display or the file cannot be written (no partial file is left).
// The scene's renderer is borrowed for the render, so the scene must not be on screen elsewhere.
void write_screenshot_png(LiverScene& scene, const std::filesystem::path& file, int width,
                          int height);

}  // namespace liversim
