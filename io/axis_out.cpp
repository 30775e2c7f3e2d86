#include "io/axis_out.hpp"

#include <algorithm>
#include <cmath>

#include "core/directions.hpp"
#include "io/csv_out.hpp"

namespace tt::io {
namespace {

std::string coefficient_name(const std::string& d, int k) {
  if (k == 0) return d + "_c0_um";
  return d + "_c" + std::to_string(k) + "_um_per_m" + (k > 1 ? std::to_string(k) : "");
}

}  // namespace

std::vector<std::string> axis_error_header(const solvers::AxisError& e) {
  std::vector<std::string> h;
  for (size_t i = 0; i < e.points.size(); ++i)
    for (const char* d : core::kDirectionNames)
      h.push_back("axis" + std::to_string(i + 1) + "_" + d + "_um");
  return h;
}

Eigen::MatrixXd axis_error_rows_um(const solvers::AxisError& e) {
  return e.values * 1e6;
}

std::vector<std::string> axis_polynomial_header(int degree) {
  std::vector<std::string> h{"time_s"};
  for (const char* d : core::kDirectionNames) {
    for (int k = 0; k <= degree; ++k) h.push_back(coefficient_name(d, k));
    h.push_back(std::string(d) + "_fit_rms_um");
    h.push_back(std::string(d) + "_fit_max_um");
  }
  return h;
}

void write_axis_polynomial_csv(const std::filesystem::path& path, const std::vector<double>& times,
                               const solvers::AxisPolynomial& poly) {
  const std::vector<std::string> header = axis_polynomial_header(poly.degree);
  const auto nt = static_cast<Eigen::Index>(times.size());
  Eigen::MatrixXd rows(nt, static_cast<Eigen::Index>(header.size()));
  for (Eigen::Index t = 0; t < nt; ++t) {
    Eigen::Index c = 0;
    rows(t, c++) = times[static_cast<size_t>(t)];
    for (int d = 0; d < 3; ++d) {
      for (int k = 0; k <= poly.degree; ++k) rows(t, c++) = poly.coefficients[d](t, k) * 1e6;
      rows(t, c++) = poly.rms[d](t) * 1e6;
      rows(t, c++) = poly.max[d](t) * 1e6;
    }
  }
  write_csv(path, header, rows, 17);
}

nlohmann::json axis_summary_json(const solvers::AxisError& e, const solvers::AxisPolynomial& poly) {
  nlohmann::json j;
  j["points"] = e.points;
  j["positions_m"] =
      std::vector<double>(e.positions.data(), e.positions.data() + e.positions.size());
  j["degree"] = poly.degree;
  for (int d = 0; d < 3; ++d) {
    const Eigen::VectorXd last = e.values.bottomRows(1).transpose();
    double spread = 0;  // largest |error| over the points at the end [m]
    for (Eigen::Index i = 0; i < e.positions.size(); ++i)
      spread = std::max(spread, std::abs(last(3 * i + d)));
    j[core::kDirectionNames[d]] = {{"fit_rms_um_max_over_time", poly.rms[d].maxCoeff() * 1e6},
                                   {"fit_max_um_max_over_time", poly.max[d].maxCoeff() * 1e6},
                                   {"largest_point_error_at_end_um", spread * 1e6}};
  }
  return j;
}

}  // namespace tt::io
