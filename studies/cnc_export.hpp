// The fitted compensation as each controller's law (thermotwin export, docs/cnc-export.md), and
// what each law leaves of the model along the axis travel: per format the law
// (fitting::controller_law) and its error against the model on a grid of positions, per unit of
// each basis function and on sampled machine states. SI units.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "fitting/cnc_export.hpp"

namespace tt::studies {

struct CncExportInput {
  const fitting::CncModel* model = nullptr;
  /// the controllers, in the order to report them
  std::vector<fitting::CncFormat> formats;
  /// machine states to judge the laws on (#samples x #basis, fitting::basis_states); may be empty
  Eigen::MatrixXd sampled_states;
  int table_points = 51;  /// TwinCAT and Heidenhain table entries over the travel
  int grid = 1001;        /// positions over the travel where the laws are judged
};

struct FormatLaw {
  fitting::CncFormat format = fitting::CncFormat::sinumerik;
  fitting::ControllerLaw law;
  /// on fitting::unit_states: the constant alone and each basis function alone at one unit
  fitting::LawError per_unit;
  /// on the sampled states, when there are any
  std::optional<fitting::LawError> on_samples;
};

struct CncExportReport {
  std::vector<FormatLaw> laws;  /// one per format, in the input's order
};

/// Throws DataError as the laws do (a table of fewer than two points, sampled states whose columns
/// do not match the basis).
CncExportReport cnc_export(const CncExportInput& input);

}  // namespace tt::studies
