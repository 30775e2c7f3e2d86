// The feed axis in `fit` at the edge: fit.json's "axis" and axis_fit.md (the study:
// studies/axis_fit.hpp).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "studies/axis_fit.hpp"

namespace tt::io {

/// For fit.json: the feed axis, per target the chosen model (its coefficients as io::model_json
/// writes them, for `thermotwin export`), its and the network's test S_M [µm], and the
/// polynomials' residuals per source and direction [µm].
nlohmann::json axis_fit_json(const studies::AxisFit& fit);

/// The same as a short Markdown report.
std::string axis_fit_markdown(const studies::AxisFit& fit);

}  // namespace tt::io
