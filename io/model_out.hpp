// What model a study stepped (studies/model_choice.hpp), for the summary files, and the warning
// a reduced model's indicator above its tolerance earns on stderr.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "studies/model_choice.hpp"

namespace tt::io {

/// The indicator for summary files: {run, max_K, tolerance_K, above_tolerance}.
nlohmann::json indicator_json(const studies::IndicatorCheck& check);

/// The warning line (with its newline) when the indicator is above its tolerance, else empty.
std::string indicator_warning(const studies::IndicatorCheck& check);

/// A campaign's model (fit.json, placement.json): {kind: full, nodes} or {kind: reduced, rom (the
/// file's absolute path, or "built on the fly"), built_from | build_s, order, nodes, indicator}.
nlohmann::json campaign_model_json(const studies::ModelUsed& model);

}  // namespace tt::io
