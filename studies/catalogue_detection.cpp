#include "studies/catalogue_detection.hpp"

#include <variant>

#include "calibration/model.hpp"
#include "core/errors.hpp"
#include "solvers/reduction.hpp"
#include "studies/estimation_input.hpp"

namespace tt::studies {

namespace {

/// The parameter that changes the films `entries` (weights `weights`) by `share` of their
/// declared coefficients.
double film_parameter(const std::vector<int>& entries, const std::vector<double>& weights,
                      const core::CaseSpec& declared, double share) {
  if (entries.empty() || weights.empty() || weights.front() == 0) return 0;
  const auto entry = static_cast<std::size_t>(entries.front());
  return share * declared.thermal.convection.at(entry).h / weights.front();
}

}  // namespace

double detection_size(const calibration::Candidate& c, const core::CaseSpec& declared,
                      const CatalogueSizes& sizes) {
  using namespace calibration;
  if (const auto* h = std::get_if<HeatInput>(&c.effect))
    return h->area > 0 ? sizes.heat_w / h->area : 0;
  if (const auto* f = std::get_if<SpeedDependentConvection>(&c.effect))
    return film_parameter(f->entries, f->weights, declared, sizes.film_share);
  if (const auto* f = std::get_if<BoundaryConductance>(&c.effect))
    return film_parameter(f->entries, f->weights, declared, sizes.film_share);
  if (std::holds_alternative<TemperatureDependentHeat>(c.effect))
    return sizes.source_coefficient_per_k;
  if (const auto* m = std::get_if<MaterialParameter>(&c.effect))
    return m->field == MaterialField::expansion ? 0 : sizes.material_change;
  if (std::holds_alternative<AmbientTemperature>(c.effect)) return sizes.air_k;
  return 0;
}

CatalogueDetection catalogue_detection(const mesh::TetMesh& mesh, const core::CaseSpec& declared,
                                       const std::vector<core::CaseSpec>& runs,
                                       const CatalogueDetectionInput& input,
                                       const solvers::Progress& progress) {
  if (runs.empty()) throw core::DataError("detection placement on the catalogue: no run");
  if (!(input.sustain_s > 0))
    throw core::DataError("detection placement on the catalogue: held for " +
                          std::to_string(input.sustain_s) + " s: expected > 0");
  const calibration::Readout r =
      calibration::temperature_readout(mesh, declared, input.names, input.points);
  const calibration::MarchModel model =
      input.full_order ? calibration::MarchModel(mesh, declared)
                       : calibration::MarchModel(mesh, declared, r, solvers::ReductionOptions{});
  std::vector<Eigen::VectorXd> times;
  for (const auto& run : runs) times.push_back(reading_times(run, input.sample_s));
  const std::vector<calibration::Candidate> cands =
      calibration::heat_flow_candidates(model, declared, r, runs, times, input.catalogue, progress);
  std::vector<std::string> effects, kinds;
  std::vector<std::vector<Eigen::MatrixXd>> changes;
  CatalogueDetection out;
  std::vector<double> sizes;
  const auto channels = static_cast<Eigen::Index>(input.names.size());
  for (const auto& c : cands) {
    const double size = detection_size(c, declared, input.sizes);
    if (size == 0) continue;
    effects.push_back(c.name);
    out.effects.push_back(c.effect);
    sizes.push_back(size);
    kinds.push_back(calibration::kind_name(calibration::kind(c)));
    changes.emplace_back();
    for (std::size_t k = 0; k < runs.size(); ++k) {
      // Columns (#readings #channels, channels outermost) x #parameters: the air's knots sum to
      // an offset over the whole run, every other candidate has one parameter.
      const Eigen::VectorXd column = c.columns[k].rowwise().sum();
      changes.back().push_back(
          size * Eigen::Map<const Eigen::MatrixXd>(column.data(), times[k].size(), channels));
    }
  }
  out.problem = placement::detection_problem(
      effects, changes, Eigen::VectorXd::Constant(channels, input.sensor_sigma_k),
      sustain_readings(input.sustain_s, input.sample_s));
  out.problem.weights = placement::weights_per_kind(kinds);
  out.problem.kinds = std::move(kinds);
  out.sizes =
      Eigen::Map<const Eigen::VectorXd>(sizes.data(), static_cast<Eigen::Index>(sizes.size()));
  return out;
}

}  // namespace tt::studies
