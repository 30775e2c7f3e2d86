#include "io/calibration_head.hpp"

namespace tt::io {
namespace {

using nlohmann::json;

/// {rms, max_abs, mae} of one channel, suffixed with its unit.
json figures_json(const core::ErrorFigures& f, bool temperature) {
  const double scale = temperature ? 1.0 : 1e6;
  const std::string unit = temperature ? "_K" : "_um";
  return {{"rms" + unit, f.rms * scale},
          {"max_abs" + unit, f.max_abs * scale},
          {"mae" + unit, f.mae * scale}};
}

json totals_json(const std::optional<double>& temperature_rms_K, const std::string& note,
                 double displacement_rms_um, const json& channels) {
  json j{{"temperature_rms_K", temperature_rms_K ? json(*temperature_rms_K) : json(nullptr)},
         {"displacement_rms_um", displacement_rms_um},
         {"channels", channels}};
  if (!temperature_rms_K && !note.empty()) j["temperature_note"] = note;
  return j;
}

}  // namespace

json calibration_head_json(const CalibrationHead& h) {
  json before = json::object(), after = json::object(), worse = json::array();
  for (const auto& c : h.channels) {
    before[c.id] = figures_json(c.before, c.temperature);
    after[c.id] = figures_json(c.after, c.temperature);
    after[c.id]["worse_than_before"] = c.worse_after_than_before();
    if (c.worse_after_than_before()) worse.push_back(c.id);
  }
  return {{"format", "thermotwin-calibration/1"},
          {"mode", h.mode},
          {"training_runs", h.training_runs},
          {"test_runs", h.test_runs},
          {"before", totals_json(h.temperature_rms_K_before, h.temperature_note,
                                 h.displacement_rms_um_before, before)},
          {"after", totals_json(h.temperature_rms_K_after, h.temperature_note,
                                h.displacement_rms_um_after, after)},
          {"after_worse_than_before_on_test", worse}};
}

}  // namespace tt::io
