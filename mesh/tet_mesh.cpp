#include "mesh/tet_mesh.hpp"

namespace tt::mesh {

int named_node(const TetMesh& mesh, const std::string& id) {
  for (const auto& p : mesh.points)
    if (p.id == id) return p.node;
  return -1;
}

}  // namespace tt::mesh
