#pragma once
// The boundary surface of a tetrahedral mesh: the faces that belong to exactly one element.

#include "liversim/core/tet_mesh.h"

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

// Area-weighted vertex normals of the surface at the given node positions (unit length), written
// into `normals` as 3 floats per surface node. Allocates nothing when `normals` is already sized.
void compute_vertex_normals(const BoundarySurface& surface, const NodeArray& position,
                            std::vector<float>& normals);

}  // namespace liversim
