#pragma once
// The boundary surface of a tetrahedral mesh: the faces that belong to exactly one element.

#include "liversim/engine/tet_mesh.h"

#include <array>
#include <vector>

namespace liversim {

struct BoundarySurface {
  std::vector<NodeIndex> nodes;  // mesh nodes on the surface, ascending
  // Triangles as indices into `nodes`, counter-clockwise seen from outside (outward normals).
  std::vector<std::array<std::int32_t, 3>> triangles;
  std::vector<TetIndex> triangle_tet;  // the element each triangle bounds
};

// Faces shared by two elements are interior; faces of positively oriented elements used once are
// the boundary. Faces used three or more times (a non-manifold mesh) are reported as boundary.
BoundarySurface extract_surface(const TetMesh& mesh);

// Area-weighted unit vertex normals of triangles over vertex positions given as interleaved xyz,
// written as 3 floats per vertex. Allocates nothing when `normals` is already sized.
void compute_vertex_normals(const std::vector<std::array<std::int32_t, 3>>& triangles,
                            const std::vector<double>& vertex_xyz, std::vector<float>& normals);

// The surface the user sees: the boundary triangles of the physics mesh, with vertices that may sit
// off the physics nodes (on the smooth organ surface, say), each carried along by the deformation
// of a host element through fixed barycentric weights (as SOFA's barycentric mapping does).
struct VisualSurface {
  BoundarySurface surface;  // vertex i stands for physics node surface.nodes[i]
  std::vector<std::array<NodeIndex, 4>> host_nodes;
  std::vector<std::array<double, 4>> weights;

  std::size_t vertex_count() const { return surface.nodes.size(); }
};

// Visual vertices exactly on the physics nodes.
VisualSurface visual_surface_on_nodes(const TetMesh& mesh);

// Visual vertices at the given rest positions (one per boundary node, in surface.nodes order), each
// embedded in the element around its node that holds it best (largest smallest barycentric weight).
VisualSurface embed_visual_surface(const TetMesh& mesh, const BoundarySurface& surface,
                                   const std::vector<Eigen::Vector3d>& vertex_rest_m);

// Positions of the visual vertices for the given node positions, as interleaved xyz. Allocates
// nothing when `vertex_xyz` is already sized.
void map_visual_positions(const VisualSurface& visual, const NodeArray& position,
                          std::vector<double>& vertex_xyz);

// Points inside the organ (the lesions drawn in the see-through view), each carried by the
// element that holds it at rest, with host nodes and barycentric weights as VisualSurface's. A
// point is held by the element it lies in, or, just outside the organ, by the nearest element
// whose smallest weight is at least kEmbeddingReach; a point farther out (or in a piece a cut
// removed) is not held, and its weights are zero.
struct EmbeddedPoints {
  std::vector<std::array<NodeIndex, 4>> host_nodes;
  std::vector<std::array<double, 4>> weights;
  std::vector<std::uint8_t> held;
};
inline constexpr double kEmbeddingReach = -0.25;
EmbeddedPoints embed_points(const TetMesh& mesh, const std::vector<Eigen::Vector3d>& points_m);
// Positions of embedded points (as map_visual_positions).
void map_embedded_positions(const std::vector<std::array<NodeIndex, 4>>& host_nodes,
                            const std::vector<std::array<double, 4>>& weights,
                            const NodeArray& position, std::vector<double>& xyz);

}  // namespace liversim
