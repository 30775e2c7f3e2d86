// place's report at the edge (docs/placement.md): placement.json (io/placement_out.hpp's document
// with the model, the candidates and the observer's settings), mi_ranking.csv, candidates_mi.vtp
// and mi_bars_<target>.png.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "studies/place_sensors.hpp"

namespace tt::io {

/// What the report came from, for placement.json.
struct PlaceSource {
  bool sensor_noise = false;
  nlohmann::json model;       /// the thermal model that gave the histories
  std::filesystem::path rom;  /// the reduced model of observer_variance; empty: built on the fly
};

/// Writes the report's files into `dir` (a folder the caller publishes).
void write_place(const std::filesystem::path& dir, const studies::PlaceReport& report,
                 const PlaceSource& source);

}  // namespace tt::io
