#include "io/reduce_out.hpp"

#include <iomanip>
#include <sstream>

#include "core/units.hpp"
#include "io/atomic_dir.hpp"
#include "io/reduced_model_io.hpp"

namespace tt::io {
namespace {

/// The validation table as reduced_model.json records it.
nlohmann::json validation_json(const std::vector<solvers::TwinComparison>& table) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& c : table) {
    nlohmann::json drift = nlohmann::json::object();
    for (std::size_t k = 0; k < c.drift_names.size(); ++k) {
      const auto i = static_cast<Eigen::Index>(k);
      drift[c.drift_names[k]] = {{"max_error_um", c.drift_error_m(i) * core::kMicrometresPerMetre},
                                 {"peak_um", c.drift_peak_m(i) * core::kMicrometresPerMetre},
                                 {"limit_um", c.drift_limit_m(i) * core::kMicrometresPerMetre}};
    }
    rows.push_back({{"run", c.run},
                    {"shape", c.shape},
                    {"max_temperature_error_K", c.max_temperature_error_k},
                    {"worst_point", c.worst_point},
                    {"temperature_limit_K", solvers::kTwinTemperatureLimitK},
                    {"drift", drift},
                    {"passes", c.passes()}});
  }
  return rows;
}

/// validation.csv: one row per run and output column (temperatures as one row).
std::string validation_csv(const std::vector<solvers::TwinComparison>& table) {
  std::ostringstream o;
  o << std::setprecision(6) << "run,output,max_error,limit,peak,unit,passes\n";
  for (const auto& c : table) {
    o << c.run << ",temperatures," << c.max_temperature_error_k << ","
      << solvers::kTwinTemperatureLimitK << ",,K,"
      << (c.max_temperature_error_k <= solvers::kTwinTemperatureLimitK ? "yes" : "no") << "\n";
    for (std::size_t k = 0; k < c.drift_names.size(); ++k) {
      const auto i = static_cast<Eigen::Index>(k);
      o << c.run << "," << c.drift_names[k] << ","
        << c.drift_error_m(i) * core::kMicrometresPerMetre << ","
        << c.drift_limit_m(i) * core::kMicrometresPerMetre << ","
        << c.drift_peak_m(i) * core::kMicrometresPerMetre << ",um,"
        << (c.drift_error_m(i) <= c.drift_limit_m(i) ? "yes" : "no") << "\n";
    }
  }
  return o.str();
}

}  // namespace

void write_reduce(const std::filesystem::path& dir, const studies::ReduceReport& report,
                  const core::CaseSpec& spec, const mesh::TetMesh& mesh,
                  const std::filesystem::path& case_file, double total_s) {
  ReducedModelFile file;
  file.twin = report.twin;
  file.key = reduced_model_key(spec, mesh);
  file.case_name = spec.name;
  file.case_file = std::filesystem::absolute(case_file).string();
  file.info["validation"] = validation_json(report.validation);
  file.info["validation_passes"] = report.passes;
  file.info["timings"] = {{"outputs_s", report.outputs_s},
                          {"reduce_s", report.reduce_s},
                          {"validate_s", report.validate_s},
                          {"total_s", total_s}};
  write_reduced_model(dir, file);
  write_file_atomically(dir / "validation.csv", validation_csv(report.validation));
}

}  // namespace tt::io
