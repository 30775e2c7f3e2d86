#include "io/place_out.hpp"

#include <map>
#include <string>
#include <vector>

#include "io/placement_out.hpp"
#include "io/plot.hpp"
#include "io/reports.hpp"
#include "io/vtk_out.hpp"

namespace tt::io {
namespace {

nlohmann::json candidates_json(const studies::Histories& h) {
  nlohmann::json candidates = nlohmann::json::array();
  for (size_t c = 0; c < h.names.size(); ++c) {
    nlohmann::json entry{{"id", c + 1},
                         {"name", h.names[c]},
                         {"position_m", {h.positions(c, 0), h.positions(c, 1), h.positions(c, 2)}}};
    if (h.nodes[c] >= 0) entry["node"] = h.nodes[c];
    candidates.push_back(std::move(entry));
  }
  return candidates;
}

nlohmann::json estimation_json(const studies::EstimationSettings& e,
                               const std::filesystem::path& rom) {
  return {{"order", e.order},
          {"rom", rom.empty() ? std::string("built on the fly") : rom.string()},
          {"reading_interval_s", e.reading_interval_s},
          {"sensor_sigma_K", e.sensor_sigma_k},
          {"heat_walk_W_per_sqrt_h", e.noise.heat_walk_w},
          {"air_walk_K_per_sqrt_h", e.noise.air_walk_k}};
}

/// Placement for detection: the settings, each effect's best candidate, the greedy from no
/// sensor and what it and each target's observer_variance set leave unseen.
nlohmann::json detection_json(const studies::DetectionReport& d, const studies::Histories& h) {
  const auto& held = d.problem.held_sigmas;
  const auto names = [&](const std::vector<int>& effects) {
    nlohmann::json out = nlohmann::json::array();
    for (int e : effects) out.push_back(d.problem.effects[static_cast<std::size_t>(e)]);
    return out;
  };
  nlohmann::json effects = nlohmann::json::array();
  for (Eigen::Index e = 0; e < held.rows(); ++e) {
    Eigen::Index best = 0;
    const double most = held.cols() > 0 ? held.row(e).maxCoeff(&best) : 0.0;
    effects.push_back({{"name", d.problem.effects[static_cast<std::size_t>(e)]},
                       {"best_candidate",
                        held.cols() > 0 ? h.names[static_cast<std::size_t>(best)] : std::string()},
                       {"best_held_sigmas", most}});
  }
  nlohmann::json greedy = nlohmann::json::array();
  for (std::size_t k = 0; k < d.greedy.order.size(); ++k)
    greedy.push_back({{"candidate", h.names[static_cast<std::size_t>(d.greedy.order[k])]},
                      {"id", d.greedy.order[k] + 1},
                      {"effects_seen", static_cast<int>(d.greedy.scores[k])}});
  nlohmann::json by_target = nlohmann::json::object();
  for (const auto& [target, unseen] : d.unseen_by_estimation) by_target[target] = names(unseen);
  return {{"bound_sigmas", d.bound_sigmas},
          {"sustain_s", d.sustain_s},
          {"heat_W", d.sizes.heat_w},
          {"air_K", d.sizes.air_k},
          {"effects", effects},
          {"greedy", greedy},
          {"unseen", names(placement::unseen_effects(d.problem, d.greedy.order, d.bound_sigmas))},
          {"unseen_by_observer_variance", by_target}};
}

/// Placement for detection of the calibration catalogue's effects: the settings, each kind's
/// effects, each effect's best candidate, the greedy from no sensor (kinds seen) and the kinds
/// each method's largest set sees.
nlohmann::json catalogue_detection_json(const studies::CatalogueDetectionReport& d,
                                        const studies::Histories& h) {
  const auto& held = d.problem.held_sigmas;
  const auto& in = d.settings;
  nlohmann::json effects = nlohmann::json::array();
  std::map<std::string, int> per_kind;
  for (Eigen::Index e = 0; e < held.rows(); ++e) {
    const auto k = static_cast<std::size_t>(e);
    Eigen::Index best = 0;
    const double most = held.cols() > 0 ? held.row(e).maxCoeff(&best) : 0.0;
    effects.push_back({{"name", d.problem.effects[k]},
                       {"kind", d.problem.kinds[k]},
                       {"best_candidate",
                        held.cols() > 0 ? h.names[static_cast<std::size_t>(best)] : std::string()},
                       {"best_held_sigmas", most}});
    ++per_kind[d.problem.kinds[k]];
  }
  nlohmann::json greedy = nlohmann::json::array();
  for (std::size_t k = 0; k < d.greedy.order.size(); ++k) {
    const std::vector<int> so_far(d.greedy.order.begin(),
                                  d.greedy.order.begin() + static_cast<std::ptrdiff_t>(k) + 1);
    greedy.push_back(
        {{"candidate", h.names[static_cast<std::size_t>(d.greedy.order[k])]},
         {"id", d.greedy.order[k] + 1},
         {"kinds_seen", d.greedy.scores[k]},
         {"effects_seen",
          held.rows() - static_cast<Eigen::Index>(
                            placement::unseen_effects(d.problem, so_far, d.bound_sigmas).size())}});
  }
  nlohmann::json by_target = nlohmann::json::object();
  for (const auto& [target, methods] : d.kinds_seen)
    for (const auto& [method, seen] : methods) by_target[target][method] = seen;
  return {{"bound_sigmas", d.bound_sigmas},
          {"sustain_s", in.sustain_s},
          {"reading_interval_s", in.sample_s},
          {"sensor_sigma_K", in.sensor_sigma_k},
          {"model", in.full_order ? "full order" : "reduced on the candidates' rows"},
          {"sizes",
           {{"heat_W", in.sizes.heat_w},
            {"film_share", in.sizes.film_share},
            {"source_coefficient_per_K", in.sizes.source_coefficient_per_k},
            {"material_change", in.sizes.material_change},
            {"air_K", in.sizes.air_k}}},
          {"patch_spacing_m", in.catalogue.patch_spacing},
          {"patch_half_size_m", in.catalogue.patch_half_size},
          {"effects_per_kind", per_kind},
          {"effects", effects},
          {"greedy", greedy},
          {"kinds_seen_by_method", by_target}};
}

/// Each target's single-sensor MI and rank per candidate, for the point cloud.
std::vector<NamedField> mi_fields(const placement::PlacementResult& result) {
  std::vector<NamedField> fields;
  for (const auto& t : result.targets) {
    fields.push_back({"mi_bits_" + t.target, 1, t.mi_bits});
    Eigen::VectorXd rank(static_cast<Eigen::Index>(t.mi_rank.size()));
    for (size_t c = 0; c < t.mi_rank.size(); ++c) rank(static_cast<Eigen::Index>(c)) = t.mi_rank[c];
    fields.push_back({"mi_rank_" + t.target, 1, rank});
  }
  return fields;
}

/// mi_bars_<target>.png of mi_ranking.csv; thousands of surface candidates make an unreadable
/// bar chart: then the best 50.
void plot_mi_bars(const std::filesystem::path& dir, const placement::PlacementResult& result,
                  std::size_t candidates) {
  const bool many = candidates > 60;
  for (const auto& t : result.targets) {
    std::vector<std::string> bars{"bars",
                                  (dir / "mi_ranking.csv").string(),
                                  (dir / ("mi_bars_" + t.target + ".png")).string(),
                                  "--label",
                                  "id",
                                  "--value=mi_bits_" + t.target,
                                  "--title=" + std::string(many ? "best 50 candidates: " : "") +
                                      "single-sensor mutual information with " + t.target +
                                      " (formula 1)"};
    if (many) bars.insert(bars.end(), {"--sort", "--top", "50"});
    plot(bars);
  }
}

}  // namespace

void write_place(const std::filesystem::path& dir, const studies::PlaceReport& report,
                 const PlaceSource& source) {
  const studies::Histories& h = report.histories;
  nlohmann::json doc = placement_json(report.result);
  doc["sensor_noise"] = source.sensor_noise;
  doc["model"] = source.model;
  if (report.estimation) doc["observer_variance"] = estimation_json(*report.estimation, source.rom);
  if (report.detection) doc["observer_detection"] = detection_json(*report.detection, h);
  if (report.catalogue_detection)
    doc["catalogue_detection"] = catalogue_detection_json(*report.catalogue_detection, h);
  doc["candidates"] = candidates_json(h);
  write_json(dir / "placement.json", doc);
  write_mi_ranking_csv(dir / "mi_ranking.csv", report.result);
  write_point_cloud_vtp(dir / "candidates_mi.vtp", h.names, h.positions, mi_fields(report.result));
  plot_mi_bars(dir, report.result, h.names.size());
}

}  // namespace tt::io
