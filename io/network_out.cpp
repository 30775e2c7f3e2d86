#include "io/network_out.hpp"

#include "io/reports.hpp"

namespace tt::io {

nlohmann::json network_json(const studies::NetworkFigures& n) {
  const auto& net = std::get<torchnet::Network>(n.model.body);
  const auto um = [](double v) { return finite_or_null(v, 1e6); };
  nlohmann::json test_s = nlohmann::json::array();
  for (double s : n.test.s) test_s.push_back(s * 1e6);
  return {{"model", fitting::model_label(n.model.spec)},
          {"chosen", n.chosen},
          {"sensors", n.model.features.sensor_names},
          {"validation_sm_um", um(n.validation.sm)},
          {"test_s_um", test_s},
          {"test_sm_um", n.test.s.empty() ? nlohmann::json(nullptr) : um(n.test.sm)},
          {"test_s_sigma_um", n.test.s.empty() ? nlohmann::json(nullptr) : um(n.test.s_sigma)},
          {"training_seconds", net.report().seconds},
          {"epochs", net.report().epochs},
          {"best_epoch", net.report().best_epoch},
          {"time_budget_reached", net.report().budget_reached},
          {"window_stride_samples", net.options().window_stride},
          {"inference_ms_median", n.inference_ms}};
}

void write_network(const std::filesystem::path& path, const fitting::FittedModel& model) {
  std::get<torchnet::Network>(model.body).save_torchscript(path);
}

}  // namespace tt::io
