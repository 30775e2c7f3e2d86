#include "io/reports.hpp"

#include "io/atomic_dir.hpp"

namespace tt::io {

nlohmann::json mesh_report_json(const mesh::TetMesh& mesh, const mesh::MeshReport& r) {
  nlohmann::json j;
  j["nodes"] = r.nodes;
  j["tets"] = r.tets;
  j["order"] = r.order;
  j["min_dihedral_deg"] = r.min_dihedral_deg;
  j["bodies"] = nlohmann::json::object();
  for (const auto& b : r.bodies) {
    nlohmann::json body{{"volume_m3", b.volume}};
    if (b.exact_volume > 0) {
      body["exact_volume_m3"] = b.exact_volume;
      body["volume_error_rel"] = (b.volume - b.exact_volume) / b.exact_volume;
    }
    j["bodies"][b.name] = body;
  }
  j["groups"] = nlohmann::json::object();
  for (size_t g = 0; g < mesh.group_names.size(); ++g)
    j["groups"][mesh.group_names[g]] = {{"area_m2", r.group_areas[g]}};
  j["points"] = nlohmann::json::array();
  for (size_t i = 0; i < mesh.points.size(); ++i) {
    const auto& p = mesh.points[i];
    j["points"].push_back({{"id", p.id},
                           {"position", {p.position.x(), p.position.y(), p.position.z()}},
                           {"node", p.node},
                           {"distance_m", r.point_distance[i]}});
  }
  return j;
}

void write_json(const std::filesystem::path& path, const nlohmann::json& value) {
  write_file_atomically(path, value.dump(2) + "\n");
}

}  // namespace tt::io
