#include "io/placement_out.hpp"

#include <charconv>
#include <cmath>

#include "core/ids.hpp"
#include "io/atomic_dir.hpp"

namespace tt::io {

namespace {

using nlohmann::json;

/// Shortest text that reads back to the same double; "nan" for NaN.
std::string number(double v) {
  if (std::isnan(v)) return "nan";
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

json ids_json(const std::vector<core::SensorId>& ids) {
  json a = json::array();
  for (auto id : ids) a.push_back(core::index_of(id));
  return a;
}

json saturation_json(const placement::SaturationDiagnosis& d) {
  return json{{"m", d.m},
              {"saturated", d.saturated},
              {"reason", d.reason},
              {"ceiling_bits", d.ceiling_bits},
              {"score_bits", d.score_bits},
              {"margin_bits", d.margin_bits},
              {"combinations_scored", d.combinations_scored},
              {"share_near_ceiling", d.share_near_ceiling},
              {"at_ceiling", d.at_ceiling},
              {"singleton_share", d.singleton_share},
              {"shuffles", d.shuffles},
              {"shuffle_mean_bits", d.shuffle_mean_bits},
              {"shuffle_sd_bits", d.shuffle_sd_bits},
              {"shuffle_max_bits", d.shuffle_max_bits},
              {"excess_bits", d.excess_bits},
              {"p_value", d.p_value}};
}

json selection_json(const placement::Selection& s) {
  json j{{"m", s.m},
         {"ids", ids_json(s.ids)},
         {"search", s.search},
         {"score", s.score},
         {"score_kind", s.score_kind},
         {"gaussian_bits", s.gaussian_bits},
         {"seconds", s.seconds},
         {"evaluations", s.evaluations}};
  if (s.saturation) j["saturation"] = saturation_json(*s.saturation);
  return j;
}

}  // namespace

json placement_json(const placement::PlacementResult& result) {
  const auto& o = result.options;
  json doc;
  doc["samples"] = result.sample_times_s.size();
  doc["sample_time_first_s"] = result.sample_times_s.size() ? result.sample_times_s(0) : 0.0;
  doc["sample_time_last_s"] =
      result.sample_times_s.size() ? result.sample_times_s(result.sample_times_s.size() - 1) : 0.0;
  doc["temperature_bins"] = o.temperature_bins;
  doc["error_bins"] = o.error_bins;
  doc["m_max"] = o.m_max;
  doc["seed"] = o.seed;
  doc["exhaustive_limit"] = o.exhaustive_limit;
  doc["max_correlation"] = o.collinearity.max_correlation;
  doc["min_residual"] = o.collinearity.min_residual;
  doc["ksg_k"] = o.ksg_k;
  doc["ga"] = {{"population", o.ga.population},
               {"max_generations", o.ga.max_generations},
               {"stall_generations", o.ga.stall_generations},
               {"crossover_rate", o.ga.crossover_rate},
               {"mutation_rate", o.ga.mutation_rate},
               {"tournament", o.ga.tournament},
               {"elites", o.ga.elites},
               {"min_parallel_batch", o.ga.min_parallel_batch}};
  doc["candidates"] = result.ids.size();
  json twins = json::array();
  for (const auto& [kept, dropped] : result.twins)
    twins.push_back({core::index_of(result.ids[static_cast<std::size_t>(kept)]),
                     core::index_of(result.ids[static_cast<std::size_t>(dropped)])});
  doc["mirror_twins_kept_dropped"] = twins;
  doc["search_pool_size"] = result.pool.size();
  doc["pod_seconds"] = result.pod_seconds;
  json targets = json::object();
  for (const auto& t : result.targets) {
    json methods = json::object();
    for (const auto& s : t.selections)
      methods[std::string(placement::method_name(s.method))].push_back(selection_json(s));
    targets[t.target] = {{"ksg_pool_size", t.ksg_pool.size()}, {"methods", methods}};
  }
  doc["targets"] = targets;
  return doc;
}

std::string mi_ranking_csv(const placement::PlacementResult& result) {
  std::string csv = "id,x_m,y_m,z_m";
  for (const auto& t : result.targets) csv += ",mi_bits_" + t.target + ",rank_" + t.target;
  csv += '\n';
  for (std::size_t c = 0; c < result.ids.size(); ++c) {
    const auto i = static_cast<Eigen::Index>(c);
    csv += std::to_string(core::index_of(result.ids[c]));
    for (int k = 0; k < 3; ++k) csv += ',' + number(result.positions_m(i, k));
    for (const auto& t : result.targets)
      csv += ',' + number(t.mi_bits(i)) + ',' + std::to_string(t.mi_rank[c]);
    csv += '\n';
  }
  return csv;
}

void write_placement_json(const std::filesystem::path& path,
                          const placement::PlacementResult& result) {
  write_file_atomically(path, placement_json(result).dump(2) + "\n");
}

void write_mi_ranking_csv(const std::filesystem::path& path,
                          const placement::PlacementResult& result) {
  write_file_atomically(path, mi_ranking_csv(result));
}

}  // namespace tt::io
