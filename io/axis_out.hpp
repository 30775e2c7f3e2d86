// The feed axis's thermal error at the edge: the per-point columns that thermal_error.csv gains
// (axis<i>_dx_um, axis<i>_dy_um, axis<i>_dz_um, i = 1..n in the case's axis_points order) and
// axis_polynomial.csv, the coefficients a CNC takes for compensation.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "solvers/axis_error.hpp"

namespace tt::io {

/// "axis1_dx_um", "axis1_dy_um", "axis1_dz_um", "axis2_dx_um", ... (3 #points names).
std::vector<std::string> axis_error_header(const solvers::AxisError& error);

/// #times x 3 #points: the points' error in um, in the header's order.
Eigen::MatrixXd axis_error_rows_um(const solvers::AxisError& error);

/// Column names of axis_polynomial.csv: time_s, then per direction d in (dx, dy, dz):
/// d_c0_um, d_c1_um_per_m, d_c2_um_per_m2, ..., d_fit_rms_um, d_fit_max_um.
std::vector<std::string> axis_polynomial_header(int degree);

/// axis_polynomial.csv: per output time, e(p) = sum_k c_k p^k with p the axis position in m and
/// e in um, and the fit's RMS and largest residual over the points.
void write_axis_polynomial_csv(const std::filesystem::path& path, const std::vector<double>& times,
                               const solvers::AxisPolynomial& poly);

/// For summary.json: the points and positions, and the largest RMS and max residual per direction.
nlohmann::json axis_summary_json(const solvers::AxisError& error,
                                 const solvers::AxisPolynomial& poly);

}  // namespace tt::io
