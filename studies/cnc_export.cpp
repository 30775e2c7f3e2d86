#include "studies/cnc_export.hpp"

namespace tt::studies {

CncExportReport cnc_export(const CncExportInput& input) {
  const fitting::CncModel& model = *input.model;
  const Eigen::MatrixXd unit = fitting::unit_states(model);
  CncExportReport report;
  for (const fitting::CncFormat format : input.formats) {
    FormatLaw entry{format, fitting::controller_law(format, model, input.table_points), {}, {}};
    entry.per_unit = fitting::law_error(model, entry.law, unit, input.grid);
    if (input.sampled_states.rows() > 0)
      entry.on_samples = fitting::law_error(model, entry.law, input.sampled_states, input.grid);
    report.laws.push_back(std::move(entry));
  }
  return report;
}

}  // namespace tt::studies
