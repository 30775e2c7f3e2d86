// The fit commands' network (seed 004) at the edge: its figures for fit.json and its TorchScript
// file.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "fitting/models.hpp"
#include "studies/network_candidate.hpp"

namespace tt::io {

/// For fit.json's summary: validation and test S_M, S_σ, training and inference figures [µm, s].
nlohmann::json network_json(const studies::NetworkFigures& n);

/// The network inside `model` (a cnn_bigru_attention model) as TorchScript at `path`.
void write_network(const std::filesystem::path& path, const fitting::FittedModel& model);

}  // namespace tt::io
