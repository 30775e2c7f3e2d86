// fit CASE's report at the edge: fit.json (docs/schemas/fit.schema.json), modelling_record.json
// and .md, compensation.csv, sensor_count_<target>.csv and .png, held_out/<group>_temperatures.csv
// (the test groups' sensor readings, for `export --states`); on a case with feed-axis points
// axis_fit.md; with the network network_<target>.pt and network_all_outputs.pt.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/case_spec.hpp"
#include "solvers/campaign.hpp"
#include "studies/fit_on_campaign.hpp"

namespace tt::io {

/// fit.json's summary: per TCP target the chosen method, sensors and model, its test S_M and S_σ
/// beside the uncompensated drift [um], and the network's figures when there are any.
nlohmann::json campaign_fit_summary(const studies::CampaignFitReport& report);

/// Writes the report's files into `dir` (a folder the caller publishes). `runs`: the campaign's
/// duty cycles; `model`: which thermal model ran them (fit.json "model").
void write_campaign_fit(const std::filesystem::path& dir, const core::CaseSpec& spec,
                        const std::vector<solvers::CampaignRun>& runs,
                        const studies::CampaignFitReport& report, const nlohmann::json& model);

}  // namespace tt::io
