// Placement results at the edge: placement.json (per target, method and m: the chosen ids, the
// score, the time and the saturation diagnosis) and mi_ranking.csv (formula-1 MI per candidate).
// Files appear whole or not at all (temporary name, then rename).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "placement/place.hpp"

namespace tt::io {

/// The document written to placement.json: options as used, the mirror twins (kept id, dropped
/// id), and targets.<name>.methods.<method> = [one object per m: m, ids, search, score,
/// score_kind, gaussian_bits, seconds, evaluations, and for histogram_mi a saturation object].
nlohmann::json placement_json(const placement::PlacementResult& result);

/// The text of mi_ranking.csv: header `id,x_m,y_m,z_m,mi_bits_<t>,rank_<t>,...` (one pair of
/// columns per target), then one row per candidate in input order.
std::string mi_ranking_csv(const placement::PlacementResult& result);

/// Writes placement_json(result) to `path` (2-space indented). Throws core::IoError.
void write_placement_json(const std::filesystem::path& path,
                          const placement::PlacementResult& result);

/// Writes mi_ranking_csv(result) to `path`. Throws core::IoError.
void write_mi_ranking_csv(const std::filesystem::path& path,
                          const placement::PlacementResult& result);

}  // namespace tt::io
