#include "io/model_out.hpp"

#include <sstream>

namespace tt::io {

nlohmann::json indicator_json(const studies::IndicatorCheck& check) {
  const solvers::ErrorIndicator& ind = check.indicator;
  return {{"run", check.run},
          {"max_K", ind.max_k},
          {"tolerance_K", ind.tolerance_k},
          {"above_tolerance", ind.above_tolerance()}};
}

std::string indicator_warning(const studies::IndicatorCheck& check) {
  const solvers::ErrorIndicator& ind = check.indicator;
  if (!ind.above_tolerance()) return {};
  std::ostringstream s;
  s << "thermotwin: warning: the reduced model's error indicator is " << ind.max_k << " K on run '"
    << check.run << "', above its tolerance of " << ind.tolerance_k << " K: check with --full\n";
  return s.str();
}

nlohmann::json campaign_model_json(const studies::ModelUsed& model) {
  if (!model.reduced) return {{"kind", "full"}, {"nodes", model.nodes}};
  nlohmann::json j{{"kind", "reduced"}, {"order", model.order}, {"nodes", model.nodes}};
  if (model.rom_file.empty()) {
    j["rom"] = "built on the fly";
    j["build_s"] = model.build_s;
  } else {
    j["rom"] = std::filesystem::absolute(model.rom_file).string();
    j["built_from"] = model.built_from;
  }
  if (model.indicator) j["indicator"] = indicator_json(*model.indicator);
  return j;
}

}  // namespace tt::io
