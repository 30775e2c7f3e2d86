#include "io/axis_fit_out.hpp"

#include <cmath>
#include <sstream>

#include "core/directions.hpp"
#include "io/fitting_out.hpp"
#include "io/reports.hpp"

namespace tt::io {
namespace {

constexpr const char* kAxes[3] = {"x", "y", "z"};

nlohmann::json um(double v) {
  return finite_or_null(v, 1e6);
}

}  // namespace

nlohmann::json axis_fit_json(const studies::AxisFit& fit) {
  nlohmann::json targets = nlohmann::json::object();
  for (std::size_t k = 0; k < fit.linear.size(); ++k) {
    const auto& e = fit.linear[k];
    const auto& chosen = e.sensor_sets[static_cast<std::size_t>(
        e.selection.candidates[static_cast<std::size_t>(e.selection.best)].sensor_set)];
    nlohmann::json t{{"method", chosen.method},
                     {"sensors", e.model.features.sensor_names},
                     {"model", fitting::model_label(e.model.spec)},
                     {"coefficients", io::model_json(e.model)},
                     {"test_sm_um", um(e.test.sm)},
                     {"uncompensated_std_um", um(fit.uncompensated_std[k])}};
    if (!fit.network.empty())
      t["network_test_sm_um"] = um(fit.network_test[static_cast<std::size_t>(fit.targets[k])].sm);
    targets[e.target_name] = t;
  }
  nlohmann::json polynomial = nlohmann::json::object();
  for (const auto& c : fit.compensation)
    for (int d = 0; d < 3; ++d) {
      polynomial[c.source][core::kDirectionNames[d]] = {
          {"rms_um", um(c.rms_m[static_cast<std::size_t>(d)])},
          {"max_um", um(c.max_m[static_cast<std::size_t>(d)])}};
    }
  nlohmann::json j{
      {"feed_axis", {{"name", fit.feed_axis}, {"direction", kAxes[fit.direction]}}},
      {"points", fit.points},
      {"positions_m",
       std::vector<double>(fit.positions.data(), fit.positions.data() + fit.positions.size())},
      {"degree", fit.degree},
      {"test_groups", fit.linear.empty() ? nlohmann::json::array()
                                         : nlohmann::json(fit.linear.front().test_groups)},
      {"targets", targets},
      {"polynomial_residual", polynomial}};
  if (!fit.network.empty()) {
    const auto& net = std::get<torchnet::Network>(fit.network.front().body);
    nlohmann::json test = nlohmann::json::object();
    for (std::size_t k = 0; k < fit.network.size(); ++k)
      test[fit.network[k].target_name] = um(fit.network_test[k].sm);
    j["network"] = {{"model", fitting::model_label(fit.network.front().spec)},
                    {"sensors", fit.network.front().features.sensor_names},
                    {"fitted_on", fit.network.front().fitted_on},
                    {"outputs", net.outputs()},
                    {"training_seconds", net.report().seconds},
                    {"epochs", net.report().epochs},
                    {"best_epoch", net.report().best_epoch},
                    {"time_budget_reached", net.report().budget_reached},
                    {"test_sm_um", test}};
  }
  return j;
}

std::string axis_fit_markdown(const studies::AxisFit& fit) {
  std::ostringstream o;
  o.precision(3);
  o << "# The feed axis: models at the axis points and the axis polynomial\n\n"
    << fit.points.size() << " axis points, polynomial of degree " << fit.degree
    << " fitted at every time of the test groups";
  if (!fit.linear.empty()) {
    o << " (";
    for (std::size_t i = 0; i < fit.linear.front().test_groups.size(); ++i)
      o << (i ? ", " : "") << fit.linear.front().test_groups[i];
    o << ")";
  }
  o << " from each source's estimate of the axis points' error; what it leaves at the points, "
       "against the measured (simulated, with sensor noise) error.\n\n"
    << "| source | dx RMS [um] | dx max [um] | dy RMS [um] | dy max [um] | dz RMS [um] | dz max "
       "[um] |\n|---|---|---|---|---|---|---|\n";
  for (const auto& c : fit.compensation) {
    o << "| " << c.source;
    for (std::size_t d = 0; d < 3; ++d) o << " | " << c.rms_m[d] * 1e6 << " | " << c.max_m[d] * 1e6;
    o << " |\n";
  }
  o << "\n\"measured\" is the polynomial of the measured error itself: what no model's "
       "polynomial can beat.\n\n"
    << "| target | chosen linear model | sensors | test S_M [um] | network test S_M [um] | "
       "uncompensated std [um] |\n|---|---|---|---|---|---|\n";
  for (std::size_t k = 0; k < fit.linear.size(); ++k) {
    const auto& e = fit.linear[k];
    o << "| " << e.target_name << " | " << fitting::model_label(e.model.spec) << " | ";
    for (std::size_t s = 0; s < e.model.features.sensor_names.size(); ++s)
      o << (s ? ", " : "") << e.model.features.sensor_names[s];
    o << " | " << e.test.sm * 1e6 << " | ";
    if (fit.network.empty())
      o << "-";
    else
      o << fit.network_test[static_cast<std::size_t>(fit.targets[k])].sm * 1e6;
    o << " | " << fit.uncompensated_std[k] * 1e6 << " |\n";
  }
  return o.str();
}

}  // namespace tt::io
