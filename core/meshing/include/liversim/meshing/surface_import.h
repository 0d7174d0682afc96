#pragma once
// An organ from a surface model (the seed built its liver in 3ds Max): a triangle surface read
// through assimp (OBJ, STL, PLY, glTF/GLB, FBX, 3DS and more), checked to bound a solid, and
// tetrahedralised at a requested element count by Gmsh (its Delaunay mesher and optimiser). The
// model's own triangles are kept as the boundary (Gmsh's remeshing of them fails on real livers),
// so a coarse model caps how small the elements near it can be: a surface too coarse for the count
// asked gives fewer elements, which the meshing reports.

#include "liversim/engine/tet_mesh.h"
#include "liversim/meshing/surface_import_error.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace liversim {

struct TriangleSurface {
  std::vector<Eigen::Vector3d> vertices_m;
  std::vector<std::array<std::int32_t, 3>> triangles;  // counter-clockwise from outside
  double volume_m3() const;  // signed: positive when the triangles face outward
};

// The units a surface model's lengths can be in (a scenario's organ.length_unit, the CLI's
// --length-unit): a model file does not say its unit reliably, so it is always given, never
// guessed.
struct LengthUnit {
  std::string_view name;
  double metres;
};
inline constexpr LengthUnit kLengthUnits[] = {{"mm", 1e-3}, {"cm", 1e-2}, {"m", 1.0}};

// The file formats the importer reads, by extension (lower case, with the dot).
const std::vector<std::string>& surface_file_extensions();
bool is_surface_file(const std::filesystem::path& file);

// Reads every mesh of the file with its node transforms, as triangles; vertices at the same point
// are one vertex. `metres_per_unit` converts the file's lengths (0.001 for millimetres). Throws
// SurfaceImportError naming the file for an unreadable file or one without triangles.
TriangleSurface read_surface_file(const std::filesystem::path& file, double metres_per_unit);

// Why the surface bounds no solid, each problem with where it is (mm): edges used by one
// triangle (a hole), or by three or more, triangles facing against their neighbours, triangles of
// no area, and triangles crossing others. Empty when it is a closed, oriented, non-intersecting
// surface. At most `max_problems`, the count of the rest in the last.
std::vector<std::string> surface_problems(const TriangleSurface& surface, int max_problems = 8);

// A surface facing inward (negative volume) turned outward. Other problems are not repaired:
// they are reported.
void orient_outward(TriangleSurface& surface);

struct MeshingProgress {
  int attempt = 0;  // 1, 2, ...
  int max_attempts = 0;
  double element_size_mm = 0.0;
  int tet_count = 0;  // of this attempt (0 before it is meshed)
};

struct SurfaceMeshingOptions {
  int target_tet_count = 5406;
  double count_tolerance = 0.05;  // relative; the element size is adjusted until within it
  int max_attempts = 8;
  // Called before and after each attempt; returning false cancels (SurfaceMeshingCancelled).
  std::function<bool(const MeshingProgress&)> progress;
};

class SurfaceMeshingCancelled : public SurfaceImportError {
 public:
  SurfaceMeshingCancelled() : SurfaceImportError("meshing was cancelled") {}
};

// Tetrahedralises the solid the surface bounds, with positively oriented elements and the
// element count within the tolerance (or the closest of max_attempts). Refuses, naming the
// problems, a surface with surface_problems(). Gmsh keeps one global state: calls are serialised.
TetMesh tetrahedralise_surface(const TriangleSurface& surface,
                               const SurfaceMeshingOptions& options);

}  // namespace liversim
