#pragma once
// What a mesh reader promises of the mesh it returns (mesh_io.h), checked by the mesh fuzz
// targets: every corner a node, four different nodes per element, positively oriented, finite
// coordinates, and named sets of valid, sorted, distinct indices.

#include "fuzz_support.h"
#include "liversim/engine/tet_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace liversim::fuzz {

template <typename Index>
bool valid_set(const std::vector<Index>& members, std::size_t count) {
  return std::is_sorted(members.begin(), members.end()) &&
         std::adjacent_find(members.begin(), members.end()) == members.end() &&
         std::all_of(members.begin(), members.end(),
                     [&](Index i) { return i >= 0 && static_cast<std::size_t>(i) < count; });
}

inline void check_mesh(const TetMesh& mesh) {
  const std::size_t nodes = mesh.node_count();
  LIVERSIM_FUZZ_CHECK(nodes > 0 && mesh.tet_count() > 0);
  LIVERSIM_FUZZ_CHECK(mesh.region.size() == mesh.tet_count());
  for (std::size_t n = 0; n < nodes; ++n)
    LIVERSIM_FUZZ_CHECK(mesh.rest_position_m.at(n).allFinite());
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    const auto corners = mesh.tet(e);
    for (int c = 0; c < 4; ++c) {
      LIVERSIM_FUZZ_CHECK(corners[c] >= 0 && static_cast<std::size_t>(corners[c]) < nodes);
      for (int d = c + 1; d < 4; ++d) LIVERSIM_FUZZ_CHECK(corners[c] != corners[d]);
    }
    LIVERSIM_FUZZ_CHECK(mesh.rest_volume_m3(e) > 0.0);
  }
  for (const auto& [name, members] : mesh.node_sets) LIVERSIM_FUZZ_CHECK(valid_set(members, nodes));
  for (const auto& [name, members] : mesh.element_sets)
    LIVERSIM_FUZZ_CHECK(valid_set(members, mesh.tet_count()));
}

}  // namespace liversim::fuzz
