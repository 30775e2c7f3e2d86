#include "fitting/compensation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.hpp"
#include "core/text.hpp"

namespace tt::fitting {

namespace {

int column_of(const std::string& name, const std::vector<std::string>& columns,
              const FittedModel& model, const char* what) {
  const auto it = std::find(columns.begin(), columns.end(), name);
  if (it != columns.end()) return static_cast<int>(it - columns.begin());
  const std::string listed = core::joined(columns);
  throw core::DataError("column '" + name + "' is missing: the model of target '" +
                        model.target_name + "' reads " + what + " '" + name + "'; the stream has " +
                        (listed.empty() ? "none" : listed));
}

/// The model's prediction [m] from one row of regressors.
double body_value(const FittedModel& model, const Eigen::VectorXd& x) {
  if (const auto* linear = std::get_if<LinearFit>(&model.body))
    return linear->intercept + x.dot(linear->coefficients);
  return ppr_prediction(std::get<PprModel>(model.body), x.transpose())(0);
}

}  // namespace

Compensator::Compensator(const std::vector<FittedModel>& models,
                         const std::vector<std::string>& columns, const Eigen::VectorXd& sigma) {
  if (models.empty()) throw core::DataError("compensator: no model to step");
  if (sigma.size() != 0 && sigma.size() != static_cast<Eigen::Index>(models.size()))
    throw core::DataError("compensator: " + std::to_string(sigma.size()) + " sigmas for " +
                          std::to_string(models.size()) + " models");
  step_.sigma = sigma;
  for (const FittedModel& model : models) {
    const bool linear = std::holds_alternative<LinearFit>(model.body);
    if (!linear && !std::holds_alternative<PprModel>(model.body))
      throw core::DataError("the model of target '" + model.target_name + "' is of kind '" +
                            kind_name(model.spec.kind) +
                            "', which compensate cannot step sample by sample");
    FittedModel bound = model;
    bound.features.sensors.clear();
    bound.features.inputs.clear();
    for (const std::string& s : model.features.sensor_names)
      bound.features.sensors.push_back(column_of(s, columns, model, "sensor"));
    for (const std::string& s : model.features.input_names)
      bound.features.inputs.push_back(column_of(s, columns, model, "input"));
    used_.insert(used_.end(), bound.features.sensors.begin(), bound.features.sensors.end());
    used_.insert(used_.end(), bound.features.inputs.begin(), bound.features.inputs.end());
    streams_.emplace_back(bound.features);
    models_.push_back(std::move(bound));
  }
  std::sort(used_.begin(), used_.end());
  used_.erase(std::unique(used_.begin(), used_.end()), used_.end());
  const auto n = static_cast<Eigen::Index>(columns.size());
  last_good_ = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
  sample_ = last_good_;
  step_.predicted = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(models_.size()),
                                              std::numeric_limits<double>::quiet_NaN());
}

const LiveStep& Compensator::next(double time, const Eigen::Ref<const Eigen::VectorXd>& values) {
  if (values.size() != last_good_.size())
    throw core::DataError("compensator: a sample of " + std::to_string(values.size()) +
                          " values for " + std::to_string(last_good_.size()) + " columns");
  step_.held.clear();
  if (started_ && !(time > streams_.front().last_time())) {
    step_.status = SampleStatus::late;
    return step_;
  }
  if (!started_ && !std::isfinite(time)) {
    step_.status = SampleStatus::waiting;
    return step_;
  }
  for (int c : used_) {
    if (std::isfinite(values(c))) {
      sample_(c) = last_good_(c) = values(c);
    } else {
      sample_(c) = last_good_(c);
      step_.held.push_back(c);
    }
  }
  if (!started_ && !step_.held.empty()) {
    // The increments start from the first complete sample, as a measured group does.
    step_.status = SampleStatus::waiting;
    return step_;
  }
  started_ = true;
  for (std::size_t m = 0; m < models_.size(); ++m)
    step_.predicted(static_cast<Eigen::Index>(m)) =
        body_value(models_[m], streams_[m].next(time, sample_, sample_));
  step_.status = step_.held.empty() ? SampleStatus::ok : SampleStatus::held;
  return step_;
}

}  // namespace tt::fitting
