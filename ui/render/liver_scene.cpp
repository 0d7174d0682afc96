#include "render/liver_scene.h"

#include "render/offscreen_png.h"
#include "render/scenario_overlay.h"

#include "liversim/haptics/haptics.h"
#include "liversim/interaction/cutting.h"
#include "liversim/meshing/surface_import.h"
#include "liversim/scenario/data_paths.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellPicker.h>
#include <vtkFloatArray.h>
#include <vtkLight.h>
#include <vtkLineSource.h>
#include <vtkMatrix4x4.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderStepsPass.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSSAOPass.h>
#include <vtkSphereSource.h>
#include <vtkTubeFilter.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>

namespace liversim {
namespace {

constexpr double kBackgroundTop[3] = {0.16, 0.18, 0.22};
constexpr double kSteel[3] = {0.7, 0.72, 0.75};
constexpr double kBackgroundBottom[3] = {0.05, 0.05, 0.07};
// The tool models' files in resources/tools, in millimetres.
constexpr double kToolModelMetresPerUnit = 1e-3;

// The mottling's two scales: patches a few centimetres across with smaller ones on them. The
// colours are per vertex, blended across each triangle, so neither scale may be finer than two
// vertex spacings (12 mm on the built-in liver's surface, 10 mm at 10 583 elements) or the
// triangles would show.
constexpr double kMottleCoarse_m = 0.05;
constexpr double kMottleFine_m = 0.025;
constexpr double kMottleFineWeight = 0.35;
// Blended lattice values crowd around their mean (a standard deviation of 0.16 for the two scales
// together, against 0.29 for values spread evenly over [0, 1]): stretched so that the patches
// reach both ends of the palette, about 4 % of the surface beyond them (clamped).
constexpr double kMottleContrast = 1.5;

// A repeatable pseudo-random value in [0, 1) for a lattice point: an integer hash, the same on
// every run and machine (no generator state).
double lattice_value(std::int64_t i, std::int64_t j, std::int64_t k) {
  std::uint64_t h = static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ull ^
                    static_cast<std::uint64_t>(j) * 0xC2B2AE3D27D4EB4Full ^
                    static_cast<std::uint64_t>(k) * 0x165667B19E3779F9ull;
  h ^= h >> 33;
  h *= 0xFF51AFD7ED558CCDull;
  h ^= h >> 33;
  h *= 0xC4CEB9FE1A85EC53ull;
  h ^= h >> 33;
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

// Value noise in [0, 1] at `p` (in lattice cells): the eight surrounding lattice values blended
// with a quintic fade, whose first two derivatives vanish at the cells' faces, so the pattern has
// no creases.
double value_noise(const Eigen::Vector3d& p) {
  const Eigen::Vector3d cell = p.array().floor();
  const auto fade = [](double t) { return t * t * t * (t * (6.0 * t - 15.0) + 10.0); };
  const Eigen::Vector3d f = p - cell;
  const double w[3] = {fade(f.x()), fade(f.y()), fade(f.z())};
  const auto i = static_cast<std::int64_t>(cell.x()), j = static_cast<std::int64_t>(cell.y()),
             k = static_cast<std::int64_t>(cell.z());
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const int di = corner & 1, dj = (corner >> 1) & 1, dk = (corner >> 2) & 1;
    value += (di ? w[0] : 1.0 - w[0]) * (dj ? w[1] : 1.0 - w[1]) * (dk ? w[2] : 1.0 - w[2]) *
             lattice_value(i + di, j + dj, k + dk);
  }
  return value;
}

// The capsule-covered tissue's colour at a rest position, as 8-bit RGB.
std::array<unsigned char, 3> tissue_colour(const Eigen::Vector3d& rest_m) {
  // The fine scale's lattice is offset so that its cells' corners do not line up with the coarse.
  const double mottle =
      (1.0 - kMottleFineWeight) * value_noise(rest_m / kMottleCoarse_m) +
      kMottleFineWeight * value_noise(rest_m / kMottleFine_m + Eigen::Vector3d(17.3, 5.1, 9.7));
  const double t = std::clamp(0.5 + kMottleContrast * (mottle - 0.5), 0.0, 1.0);
  std::array<unsigned char, 3> rgb;
  for (int c = 0; c < 3; ++c)
    rgb[c] = static_cast<unsigned char>(
        std::lround(255.0 * ((1.0 - t) * kTissueDarkColour[c] + t * kTissueLightColour[c])));
  return rgb;
}

vtkSmartPointer<vtkActor> model_actor(const VisualMesh& mesh) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToFloat();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.position_m.size()));
  vtkNew<vtkFloatArray> normals;
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(static_cast<vtkIdType>(mesh.normal.size()));
  for (std::size_t v = 0; v < mesh.position_m.size(); ++v) {
    points->SetPoint(static_cast<vtkIdType>(v), mesh.position_m[v].data());
    normals->SetTypedTuple(static_cast<vtkIdType>(v), mesh.normal[v].data());
  }
  vtkNew<vtkCellArray> triangles;
  for (const auto& t : mesh.triangles) {
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    triangles->InsertNextCell(3, ids);
  }
  vtkNew<vtkPolyData> polydata;
  polydata->SetPoints(points);
  polydata->GetPointData()->SetNormals(normals);
  polydata->SetPolys(triangles);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(polydata);
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  vtkProperty* property = actor->GetProperty();
  property->SetColor(mesh.diffuse_colour[0], mesh.diffuse_colour[1], mesh.diffuse_colour[2]);
  property->SetInterpolationToPhong();
  property->SetSpecular(mesh.specular);
  property->SetSpecularPower(mesh.shininess);
  actor->VisibilityOff();
  actor->PickableOff();  // picks hit the liver through the tool
  return actor;
}

}  // namespace

std::vector<LesionShape> visible_lesions(const Scenario& scenario) {
  std::vector<LesionShape> shapes;
  for (const LesionSpec& lesion : scenario.lesions)
    if (!lesion.hidden) shapes.push_back({to_metres(lesion.centre_mm), to_metres(lesion.radii_mm)});
  return shapes;
}

ToolModels load_tool_models(const std::filesystem::path& folder) {
  ToolModels models;
  const auto read = [&](const char* file, std::optional<VisualModel>& model) {
    try {
      model = read_visual_model(folder / file, kToolModelMetresPerUnit);
    } catch (const std::exception& e) {
      models.problem += (models.problem.empty() ? "" : "; ") + std::string(e.what());
    }
  };
  read("probe.obj", models.probe);
  read("forceps-body.obj", models.forceps_body);
  read("forceps-jaw.obj", models.forceps_jaw);
  read("scalpel.obj", models.scalpel);
  return models;
}

ToolModels load_tool_models() {
  return load_tool_models(shipped_resources_folder() / "tools");
}

void LiverScene::ModelActors::show(bool shown) {
  for (auto& actor : actors) actor->SetVisibility(shown);
}

void LiverScene::ModelActors::place(const Eigen::Affine3d& tool_pose) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) pose->SetElement(r, c, tool_pose.matrix()(r, c));
}

void LiverScene::set_tool_models(const ToolModels& models) {
  const auto make = [&](const std::optional<VisualModel>& model, ModelActors& into) {
    for (auto& actor : into.actors) renderer_->RemoveActor(actor);
    into.actors.clear();
    if (!model) return;
    for (const VisualMesh& mesh : *model) {
      into.actors.push_back(model_actor(mesh));
      into.actors.back()->SetUserMatrix(into.pose);
      renderer_->AddActor(into.actors.back());
    }
  };
  // The forceps are drawn from a model only with their jaws.
  const bool forceps = models.forceps_body && models.forceps_jaw;
  for (HandTool& hand : hand_tools_) {
    make(models.probe, hand.models[static_cast<int>(ToolKind::probe)]);
    make(models.scalpel, hand.models[static_cast<int>(ToolKind::scalpel)]);
    make(forceps ? models.forceps_body : std::nullopt,
         hand.models[static_cast<int>(ToolKind::forceps)]);
    for (ModelActors& jaw : hand.forceps_jaws)
      make(forceps ? models.forceps_jaw : std::nullopt, jaw);
  }
}

LiverScene::LiverScene(const TetMesh& mesh, VisualSurface visual)
    : uncut_visual_(visual), uncut_mesh_(mesh) {
  std::vector<double> smooth_xyz;
  map_visual_positions(visual, mesh.rest_position_m, smooth_xyz);
  for (std::size_t v = 0; v < visual.vertex_count(); ++v) {
    const Eigen::Vector3d node = mesh.rest_position_m.at(visual.surface.nodes[v]);
    smooth_vertex_at_[{node.x(), node.y(), node.z()}] =
        Eigen::Vector3d(smooth_xyz[3 * v], smooth_xyz[3 * v + 1], smooth_xyz[3 * v + 2]);
  }
  points_->SetDataTypeToDouble();
  normals_->SetNumberOfComponents(3);
  normals_->SetName("Normals");
  vertex_colours_->SetNumberOfComponents(3);
  vertex_colours_->SetName("Colours");
  polydata_->SetPoints(points_);
  polydata_->GetPointData()->SetNormals(normals_);
  polydata_->GetPointData()->SetScalars(vertex_colours_);
  set_surface(std::move(visual), {}, mesh.rest_position_m, mesh.rest_position_m);

  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(polydata_);
  // The vertices' own colours (the mottled surface, or the interior where cut) in place of the
  // diffuse and ambient colour; the highlights stay white, as on a moist surface.
  mapper->SetScalarModeToUsePointData();
  mapper->SetColorModeToDirectScalars();
  liver_actor_->SetMapper(mapper);
  vtkProperty* tissue = liver_actor_->GetProperty();
  tissue->SetInterpolationToPhong();
  tissue->SetAmbient(0.12);
  tissue->SetDiffuse(0.85);
  // A moist capsule: small, bright white highlights.
  tissue->SetSpecular(0.35);
  tissue->SetSpecularPower(50.0);
  renderer_->AddActor(liver_actor_);

  vtkNew<vtkSphereSource> sphere;
  sphere->SetRadius(0.004);
  sphere->SetThetaResolution(16);
  sphere->SetPhiResolution(16);
  vtkNew<vtkPolyDataMapper> marker_mapper;
  marker_mapper->SetInputConnection(sphere->GetOutputPort());
  grab_marker_->SetMapper(marker_mapper);
  grab_marker_->GetProperty()->SetColor(0.75, 0.8, 0.85);
  grab_marker_->GetProperty()->SetSpecular(0.6);
  grab_marker_->VisibilityOff();
  grab_marker_->PickableOff();
  renderer_->AddActor(grab_marker_);

  for (HandTool& hand : hand_tools_)
    for (ToolPart& part : hand.parts) {
      part.line = vtkSmartPointer<vtkLineSource>::New();
      part.tube = vtkSmartPointer<vtkTubeFilter>::New();
      part.tube->SetInputConnection(part.line->GetOutputPort());
      part.tube->SetNumberOfSides(20);
      auto add_actor = [&](vtkAlgorithmOutput* output) {
        auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
        mapper->SetInputConnection(output);
        auto actor = vtkSmartPointer<vtkActor>::New();
        actor->SetMapper(mapper);
        actor->GetProperty()->SetColor(kSteel[0], kSteel[1], kSteel[2]);
        actor->GetProperty()->SetSpecular(0.8);
        actor->GetProperty()->SetSpecularPower(40.0);
        actor->VisibilityOff();
        actor->PickableOff();  // picks hit the liver through the tool
        renderer_->AddActor(actor);
        return actor;
      };
      part.actors[0] = add_actor(part.tube->GetOutputPort());
      for (int k = 0; k < 2; ++k) {
        part.end[k] = vtkSmartPointer<vtkSphereSource>::New();
        part.end[k]->SetThetaResolution(20);
        part.end[k]->SetPhiResolution(12);
        part.actors[1 + k] = add_actor(part.end[k]->GetOutputPort());
      }
    }

  lesion_points_->SetDataTypeToDouble();
  lesion_normals_->SetNumberOfComponents(3);
  lesion_polydata_->SetPoints(lesion_points_);
  lesion_polydata_->GetPointData()->SetNormals(lesion_normals_);
  vtkNew<vtkPolyDataMapper> lesion_mapper;
  lesion_mapper->SetInputData(lesion_polydata_);
  lesion_actor_->SetMapper(lesion_mapper);
  lesion_actor_->GetProperty()->SetColor(kLesionColour[0], kLesionColour[1], kLesionColour[2]);
  lesion_actor_->GetProperty()->SetInterpolationToPhong();
  lesion_actor_->GetProperty()->SetSpecular(0.2);
  lesion_actor_->GetProperty()->SetSpecularPower(12.0);
  lesion_actor_->PickableOff();
  lesion_actor_->VisibilityOff();
  renderer_->AddActor(lesion_actor_);

  renderer_->GradientBackgroundOn();
  renderer_->SetBackground(kBackgroundBottom[0], kBackgroundBottom[1], kBackgroundBottom[2]);
  renderer_->SetBackground2(kBackgroundTop[0], kBackgroundTop[1], kBackgroundTop[2]);
  // A headlight so the surface facing the user is always lit, plus a key light from above like
  // an operating lamp, which gives the specular highlights of a moist surface.
  vtkNew<vtkLight> headlight;
  headlight->SetLightTypeToHeadlight();
  headlight->SetIntensity(0.75);
  renderer_->AddLight(headlight);
  vtkNew<vtkLight> lamp;
  lamp->SetLightTypeToSceneLight();
  lamp->SetPosition(0.1, 0.6, 0.5);
  lamp->SetFocalPoint(0.0, 0.0, 0.0);
  lamp->SetIntensity(0.45);
  renderer_->AddLight(lamp);

  occlusion_pass_->SetDelegatePass(scene_passes_);
  // Creases between lobes, around the hilum and along a cut are a centimetre or two deep on a
  // liver about 25 cm across: samples within 2 cm.
  occlusion_pass_->SetRadius(0.02);
  // The pass keeps view-space positions as half floats, whose steps are 0.5 mm at the camera's
  // distance (0.4 to 0.8 m): a sample must lie 2 steps behind a surface to count, or a smooth
  // surface would shadow itself in speckles.
  occlusion_pass_->SetBias(0.001);
  // VTK's 32 samples a pixel, blurred over its neighbours to smooth their grain.
  occlusion_pass_->SetKernelSize(32);
  occlusion_pass_->BlurOn();

  picker_->SetTolerance(0.0005);
  picker_->PickFromListOn();
  picker_->AddPickList(liver_actor_);
  reset_camera();
}

LiverScene::~LiverScene() = default;

vtkRenderer* LiverScene::renderer() const {
  return renderer_.Get();
}

void LiverScene::set_surface(VisualSurface visual, const std::vector<std::uint8_t>& cut_faces,
                             const NodeArray& rest_position_m, const NodeArray& position_m) {
  visual_ = std::move(visual);
  const BoundarySurface& surface = visual_.surface;
  const std::size_t vertex_count = surface.nodes.size();
  const auto is_cut = [&](std::size_t t) { return t < cut_faces.size() && cut_faces[t]; };
  // The cut faces are drawn apart from the capsule: a vertex on the cut's rim is drawn twice, once
  // for each, so that each side has its own colour up to the edge and its own normal (the rim is
  // an edge, not a bend).
  std::vector<std::uint8_t> on_capsule(vertex_count, 0);
  for (std::size_t t = 0; t < surface.triangles.size(); ++t)
    if (!is_cut(t))
      for (std::int32_t v : surface.triangles[t]) on_capsule[static_cast<std::size_t>(v)] = 1;
  drawn_triangles_ = surface.triangles;
  rim_copy_of_.clear();
  std::vector<std::int32_t> rim_copy(vertex_count, -1);
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    if (!is_cut(t)) continue;
    for (std::int32_t& v : drawn_triangles_[t]) {
      const auto original = static_cast<std::size_t>(v);
      if (!on_capsule[original]) continue;
      if (rim_copy[original] < 0) {
        rim_copy[original] = static_cast<std::int32_t>(vertex_count + rim_copy_of_.size());
        rim_copy_of_.push_back(v);
      }
      v = rim_copy[original];
    }
  }
  const auto drawn_count = static_cast<vtkIdType>(vertex_count + rim_copy_of_.size());
  points_->SetNumberOfPoints(drawn_count);
  normals_->SetNumberOfTuples(drawn_count);
  drawn_xyz_.resize(3 * static_cast<std::size_t>(drawn_count));

  // The colours are made here, once per surface: a vertex keeps its colour however the tissue
  // moves, and a frame only moves the vertices.
  map_visual_positions(visual_, rest_position_m, rest_xyz_);
  vertex_colours_->SetNumberOfTuples(drawn_count);
  for (std::size_t v = 0; v < vertex_count; ++v) {
    const auto rgb = tissue_colour(
        Eigen::Vector3d(rest_xyz_[3 * v], rest_xyz_[3 * v + 1], rest_xyz_[3 * v + 2]));
    vertex_colours_->SetTypedTuple(static_cast<vtkIdType>(v), rgb.data());
  }
  unsigned char cut_rgb[3];
  for (int c = 0; c < 3; ++c)
    cut_rgb[c] = static_cast<unsigned char>(std::lround(255.0 * kCutColour[c]));
  vtkNew<vtkCellArray> triangles;
  triangles->AllocateExact(static_cast<vtkIdType>(drawn_triangles_.size()),
                           static_cast<vtkIdType>(3 * drawn_triangles_.size()));
  for (std::size_t t = 0; t < drawn_triangles_.size(); ++t) {
    const vtkIdType ids[3] = {drawn_triangles_[t][0], drawn_triangles_[t][1],
                              drawn_triangles_[t][2]};
    triangles->InsertNextCell(3, ids);
    if (is_cut(t))
      for (vtkIdType id : ids) vertex_colours_->SetTypedTuple(id, cut_rgb);
  }
  polydata_->SetPolys(triangles);
  vertex_colours_->Modified();
  update_positions(position_m);
}

void LiverScene::show_tool(Hand which, const std::optional<Tool>& tool) {
  HandTool& hand = hand_tools_[hand_index(which)];
  for (ModelActors& model : hand.models) model.show(false);
  for (ModelActors& jaw : hand.forceps_jaws) jaw.show(false);
  // The models are made at the default sizes: another tool geometry is drawn as its capsules.
  if (tool && has_model(tool->kind) && tool->geometry == ToolGeometry{}) {
    show_tool(which, std::span<const Capsule>());
    const Eigen::Affine3d pose = Eigen::Translation3d(tool->pose.origin_m) * tool->pose.orientation;
    ModelActors& model = hand.models[static_cast<int>(tool->kind)];
    model.place(pose);
    model.show(true);
    if (tool->kind == ToolKind::forceps) {
      // Each jaw turns about the hinge's y axis (tools.cpp, jaw_tip_local_m); the second is the
      // first turned half a turn about the shaft.
      const double angle =
          std::clamp(tool->jaw_opening, 0.0, 1.0) * tool->geometry.max_jaw_angle_rad;
      hand.forceps_jaws[0].place(pose * Eigen::AngleAxisd(-angle, Eigen::Vector3d::UnitY()));
      hand.forceps_jaws[1].place(pose * Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitZ()));
      for (ModelActors& jaw : hand.forceps_jaws) jaw.show(true);
    }
    return;
  }
  std::array<Capsule, 3> parts;
  const int count = tool ? tool_capsules(*tool, parts) : 0;
  show_tool(which, std::span<const Capsule>(parts.data(), static_cast<std::size_t>(count)));
}

void LiverScene::show_cut_model(const SimModel& model, const NodeArray& position_m) {
  const TetMesh mesh = model_mesh(model);
  BoundarySurface surface = boundary_surface(model);
  std::vector<Eigen::Vector3d> vertex_rest(surface.nodes.size());
  for (std::size_t v = 0; v < surface.nodes.size(); ++v) {
    const Eigen::Vector3d rest = mesh.rest_position_m.at(surface.nodes[v]);
    const auto smooth = smooth_vertex_at_.find({rest.x(), rest.y(), rest.z()});
    vertex_rest[v] = smooth != smooth_vertex_at_.end() ? smooth->second : rest;
  }
  VisualSurface visual = embed_visual_surface(mesh, surface, vertex_rest);
  const auto cut_faces = cut_face_flags(model, visual.surface);
  // The lesions are embedded in the new mesh before set_surface moves them: the old embedding
  // names nodes of the old mesh.
  if (!lesion_rest_m_.empty()) show_lesion_embedding(embed_points(mesh, lesion_rest_m_));
  set_surface(std::move(visual), cut_faces, mesh.rest_position_m, position_m);
}

void LiverScene::show_uncut(const NodeArray& position_m) {
  if (!lesion_rest_m_.empty()) show_lesion_embedding(uncut_lesion_embedding_);
  set_surface(uncut_visual_, {}, uncut_mesh_.rest_position_m, position_m);
}

void LiverScene::show_lesions(const std::vector<LesionShape>& lesions) {
  lesion_rest_m_.clear();
  lesion_triangles_.clear();
  // A unit sphere of 24 × 16 facets, stretched to each lesion's radii.
  constexpr int kAround = 24, kAlong = 16;
  for (const LesionShape& lesion : lesions) {
    const auto first = static_cast<std::int32_t>(lesion_rest_m_.size());
    const auto vertex = [&](int i, int j) {  // i along (pole to pole), j around
      if (i == 0) return first;
      if (i == kAlong) return first + 1 + (kAlong - 1) * kAround;
      return first + 1 + (i - 1) * kAround + j % kAround;
    };
    for (int i = 0; i <= kAlong; ++i) {
      const double polar = std::numbers::pi * i / kAlong;
      for (int j = 0; j < ((i == 0 || i == kAlong) ? 1 : kAround); ++j) {
        const double azimuth = 2.0 * std::numbers::pi * j / kAround;
        const Eigen::Vector3d unit(std::sin(polar) * std::cos(azimuth),
                                   std::sin(polar) * std::sin(azimuth), std::cos(polar));
        lesion_rest_m_.push_back(lesion.centre_m + lesion.radii_m.cwiseProduct(unit));
      }
    }
    for (int i = 0; i < kAlong; ++i)
      for (int j = 0; j < kAround; ++j) {
        const std::int32_t a = vertex(i, j), b = vertex(i, j + 1), c = vertex(i + 1, j),
                           d = vertex(i + 1, j + 1);
        // Counter-clockwise seen from outside (the sphere's z axis points to its first pole).
        if (i > 0) lesion_triangles_.push_back({a, c, b});
        if (i < kAlong - 1) lesion_triangles_.push_back({b, c, d});
      }
  }
  uncut_lesion_embedding_ = embed_points(uncut_mesh_, lesion_rest_m_);
  show_lesion_embedding(uncut_lesion_embedding_);
  update_lesion_positions(uncut_mesh_.rest_position_m);
}

std::size_t LiverScene::shown_lesion_triangle_count() const {
  return lesion_actor_->GetVisibility()
             ? static_cast<std::size_t>(lesion_polydata_->GetNumberOfCells())
             : 0;
}

void LiverScene::show_lesion_embedding(EmbeddedPoints embedding) {
  lesion_embedding_ = std::move(embedding);
  vtkNew<vtkCellArray> triangles;
  for (const auto& t : lesion_triangles_) {
    if (!lesion_embedding_.held[t[0]] || !lesion_embedding_.held[t[1]] ||
        !lesion_embedding_.held[t[2]])
      continue;  // in a piece a cut removed
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    triangles->InsertNextCell(3, ids);
  }
  lesion_polydata_->SetPolys(triangles);
  lesion_actor_->SetVisibility(triangles->GetNumberOfCells() > 0);
}

void LiverScene::update_lesion_positions(const NodeArray& position_m) {
  if (lesion_rest_m_.empty()) return;
  map_embedded_positions(lesion_embedding_.host_nodes, lesion_embedding_.weights, position_m,
                         lesion_xyz_);
  lesion_points_->SetNumberOfPoints(static_cast<vtkIdType>(lesion_rest_m_.size()));
  for (std::size_t i = 0; i < lesion_rest_m_.size(); ++i)
    lesion_points_->SetPoint(static_cast<vtkIdType>(i), lesion_xyz_[3 * i], lesion_xyz_[3 * i + 1],
                             lesion_xyz_[3 * i + 2]);
  compute_vertex_normals(lesion_triangles_, lesion_xyz_, lesion_normal_scratch_);
  lesion_normals_->SetNumberOfTuples(static_cast<vtkIdType>(lesion_rest_m_.size()));
  std::copy(lesion_normal_scratch_.begin(), lesion_normal_scratch_.end(),
            lesion_normals_->GetPointer(0));
  lesion_points_->Modified();
  lesion_normals_->Modified();
  lesion_polydata_->Modified();
}

void LiverScene::update_positions(const NodeArray& position_m) {
  map_visual_positions(visual_, position_m, vertex_xyz_);
  std::copy(vertex_xyz_.begin(), vertex_xyz_.end(), drawn_xyz_.begin());
  for (std::size_t i = 0; i < rim_copy_of_.size(); ++i)
    std::copy_n(&vertex_xyz_[3 * static_cast<std::size_t>(rim_copy_of_[i])], 3,
                &drawn_xyz_[vertex_xyz_.size() + 3 * i]);
  const std::size_t drawn_count = drawn_xyz_.size() / 3;
  for (std::size_t i = 0; i < drawn_count; ++i)
    points_->SetPoint(static_cast<vtkIdType>(i), drawn_xyz_[3 * i], drawn_xyz_[3 * i + 1],
                      drawn_xyz_[3 * i + 2]);
  compute_vertex_normals(drawn_triangles_, drawn_xyz_, normal_scratch_);
  std::copy(normal_scratch_.begin(), normal_scratch_.end(), normals_->GetPointer(0));
  points_->Modified();
  normals_->Modified();
  polydata_->Modified();
  update_lesion_positions(position_m);
}

void LiverScene::reset_camera(double aspect) {
  vtkCamera* camera = renderer_->GetActiveCamera();
  camera->SetFocalPoint(0.0, 0.0, 0.0);
  // Anterior, slightly from above and the left: a device not yet calibrated takes its axes from
  // this view (haptics.h), the headless recorder's too.
  const Eigen::Vector3d camera_m = opening_view_camera_offset_m();
  camera->SetPosition(camera_m.x(), camera_m.y(), camera_m.z());
  camera->SetViewUp(0.0, 1.0, 0.0);
  camera->SetViewAngle(30.0);
  renderer_->ResetCamera(polydata_->GetBounds());
  // ResetCamera fits the organ's bounding sphere in the vertical view angle only.
  if (aspect > 0.0 && aspect < 1.0) camera->Dolly(aspect);
  renderer_->ResetCameraClippingRange();
}

void LiverScene::set_opacity(double opacity) {
  vtkProperty* tissue = liver_actor_->GetProperty();
  tissue->SetOpacity(opacity);
  tissue->SetBackfaceCulling(opacity < 1.0);
}

double LiverScene::opacity() const {
  return liver_actor_->GetProperty()->GetOpacity();
}

void LiverScene::set_ambient_occlusion(bool on) {
  // A pass taken off keeps its framebuffer and textures until told to release them (the window
  // releases only the passes its renderers hold): released here, or they leak.
  if (!on && renderer_->GetPass() == occlusion_pass_.Get())
    if (vtkRenderWindow* window = renderer_->GetRenderWindow()) {
      window->MakeCurrent();
      occlusion_pass_->ReleaseGraphicsResources(window);
    }
  // No pass: the renderer's own default passes, as before.
  renderer_->SetPass(on ? occlusion_pass_.Get() : nullptr);
  // VTK 9.1's occlusion pass reads every pixel's view position, which the gradient background's
  // quad leaves undefined (it writes colour only): the organ's outline then darkens by chance,
  // differently each frame. With occlusion, the background is one colour, the gradient's middle,
  // which the clear writes with no position.
  renderer_->SetGradientBackground(!on);
  double bottom[3];
  for (int c = 0; c < 3; ++c)
    bottom[c] = on ? 0.5 * (kBackgroundBottom[c] + kBackgroundTop[c]) : kBackgroundBottom[c];
  renderer_->SetBackground(bottom);
}

bool LiverScene::ambient_occlusion() const {
  return renderer_->GetPass() == occlusion_pass_.Get();
}

void LiverScene::show_grab_marker(const std::optional<Eigen::Vector3d>& point_m) {
  if (point_m) grab_marker_->SetPosition(point_m->x(), point_m->y(), point_m->z());
  grab_marker_->SetVisibility(point_m.has_value());
}

void LiverScene::show_tool(Hand which, std::span<const Capsule> parts) {
  std::array<ToolPart, 3>& tool_parts = hand_tools_[hand_index(which)].parts;
  for (std::size_t i = 0; i < tool_parts.size(); ++i) {
    ToolPart& part = tool_parts[i];
    const bool shown = i < parts.size();
    for (auto& actor : part.actors) actor->SetVisibility(shown);
    if (!shown) continue;
    const Capsule& c = parts[i];
    part.line->SetPoint1(c.a_m.x(), c.a_m.y(), c.a_m.z());
    part.line->SetPoint2(c.b_m.x(), c.b_m.y(), c.b_m.z());
    part.tube->SetRadius(c.radius_m);
    // A ball (the probe's) has no length: its ends alone show it.
    part.actors[0]->SetVisibility((c.b_m - c.a_m).norm() > 0.0);
    const Eigen::Vector3d* ends[2] = {&c.a_m, &c.b_m};
    for (int k = 0; k < 2; ++k) {
      part.end[k]->SetCenter(ends[k]->x(), ends[k]->y(), ends[k]->z());
      part.end[k]->SetRadius(c.radius_m);
    }
  }
}

std::optional<ScenePick> LiverScene::pick(int display_x, int display_y) const {
  if (!picker_->Pick(display_x, display_y, 0.0, renderer_) || picker_->GetCellId() < 0)
    return std::nullopt;
  double hit[3];
  picker_->GetPickPosition(hit);
  const Eigen::Vector3d point(hit[0], hit[1], hit[2]);
  const auto& triangle = surface().triangles[static_cast<std::size_t>(picker_->GetCellId())];
  NodeIndex nearest = surface().nodes[triangle[0]];
  double best = std::numeric_limits<double>::infinity();
  for (auto local : triangle) {
    double p[3];
    points_->GetPoint(local, p);
    const double d = (Eigen::Vector3d(p[0], p[1], p[2]) - point).squaredNorm();
    if (d < best) {
      best = d;
      nearest = surface().nodes[local];
    }
  }
  return ScenePick{point, nearest};
}

Eigen::Vector3d LiverScene::display_to_world(int display_x, int display_y,
                                             const Eigen::Vector3d& on_plane_m) const {
  // The plane's depth in display coordinates, then back to world at the cursor.
  renderer_->SetWorldPoint(on_plane_m.x(), on_plane_m.y(), on_plane_m.z(), 1.0);
  renderer_->WorldToDisplay();
  const double depth = renderer_->GetDisplayPoint()[2];
  renderer_->SetDisplayPoint(display_x, display_y, depth);
  renderer_->DisplayToWorld();
  const double* w = renderer_->GetWorldPoint();
  return Eigen::Vector3d(w[0], w[1], w[2]) / w[3];
}

Eigen::Vector2d LiverScene::world_to_display(const Eigen::Vector3d& point_m) const {
  renderer_->SetWorldPoint(point_m.x(), point_m.y(), point_m.z(), 1.0);
  renderer_->WorldToDisplay();
  const double* d = renderer_->GetDisplayPoint();
  return {d[0], d[1]};
}

void write_screenshot_png(LiverScene& scene, const std::filesystem::path& file, int width,
                          int height) {
  check_offscreen_png_target(file, "render");
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(width, height);
  window->SetMultiSamples(0);
  window->AddRenderer(scene.renderer());
  scene.renderer()->ResetCameraClippingRange();
  // Give the renderer back whatever happens: it may be shown elsewhere afterwards.
  try {
    write_window_png(window, file);
  } catch (...) {
    window->RemoveRenderer(scene.renderer());
    throw;
  }
  window->RemoveRenderer(scene.renderer());
}

}  // namespace liversim
