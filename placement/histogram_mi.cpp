#include "placement/histogram_mi.hpp"

#include <cmath>
#include <string>
#include <unordered_map>

#include "core/errors.hpp"
#include "core/parallel.hpp"

namespace tt::placement {

namespace {

void require_bins(int bins, const char* what) {
  if (bins < 2 || bins > 255)
    throw core::DataError(std::string("placement.") + what + " = " + std::to_string(bins) +
                          ": must be in [2, 255] (the patent uses 20 to 40)");
}

/// The temperature cell of sample s: 8 bits per sensor, first sensor in the lowest byte.
std::uint64_t cell_key(const BinnedProblem& p, std::span<const int> set, Eigen::Index s) {
  std::uint64_t key = 0;
  for (std::size_t d = 0; d < set.size(); ++d)
    key |= static_cast<std::uint64_t>(p.t_bins(s, set[d])) << (8 * d);
  return key;
}

void require_set(const BinnedProblem& p, std::span<const int> set) {
  if (set.empty() || set.size() > 7)
    throw core::DataError("placement: joint histogram of " + std::to_string(set.size()) +
                          " sensors: expected 1 to 7 (one byte per sensor in the cell key)");
  for (int c : set)
    if (c < 0 || c >= p.t_bins.cols())
      throw core::DataError("placement: candidate column " + std::to_string(c) + " outside [0, " +
                            std::to_string(p.t_bins.cols()) + ")");
}

}  // namespace

std::vector<std::uint8_t> equal_width_bins(const Eigen::VectorXd& values, int bins) {
  require_bins(bins, "bins");
  std::vector<std::uint8_t> out(static_cast<std::size_t>(values.size()), 0);
  if (values.size() == 0) return out;
  const double lo = values.minCoeff();
  const double hi = values.maxCoeff();
  if (!(hi > lo)) return out;
  const double width = (hi - lo) / bins;
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    int b = static_cast<int>(std::floor((values(i) - lo) / width));
    if (b >= bins) b = bins - 1;  // the maximum (and round-off just below it) in the last bin
    if (b < 0) b = 0;
    out[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(b);
  }
  return out;
}

BinnedProblem binned_problem(const Eigen::MatrixXd& temperatures, const Eigen::VectorXd& error,
                             int temperature_bins, int error_bins) {
  require_bins(temperature_bins, "temperature_bins");
  require_bins(error_bins, "error_bins");
  if (temperatures.rows() != error.size())
    throw core::DataError("placement: " + std::to_string(temperatures.rows()) +
                          " temperature samples but " + std::to_string(error.size()) +
                          " error samples: expected the same sample times");
  BinnedProblem p;
  p.samples = static_cast<int>(error.size());
  p.temperature_bins = temperature_bins;
  p.error_bins = error_bins;
  p.t_bins.resize(temperatures.rows(), temperatures.cols());
  for (Eigen::Index j = 0; j < temperatures.cols(); ++j) {
    const auto b = equal_width_bins(temperatures.col(j), temperature_bins);
    for (Eigen::Index s = 0; s < temperatures.rows(); ++s)
      p.t_bins(s, j) = b[static_cast<std::size_t>(s)];
  }
  p.y_bins = equal_width_bins(error, error_bins);
  return p;
}

double pair_mi_bits(std::span<const std::uint8_t> y_bins, int error_bins,
                    std::span<const std::uint8_t> t_bins, int temperature_bins) {
  if (y_bins.size() != t_bins.size() || y_bins.empty())
    throw core::DataError("placement: formula 1 on series of " + std::to_string(y_bins.size()) +
                          " and " + std::to_string(t_bins.size()) +
                          " samples: expected equal, non-zero lengths");
  const auto m = static_cast<std::size_t>(error_bins);
  const auto n = static_cast<std::size_t>(temperature_bins);
  std::vector<int> joint(m * n, 0), py(m, 0), pt(n, 0);
  for (std::size_t s = 0; s < y_bins.size(); ++s) {
    ++joint[y_bins[s] * n + t_bins[s]];
    ++py[y_bins[s]];
    ++pt[t_bins[s]];
  }
  const double total = static_cast<double>(y_bins.size());
  double bits = 0.0;
  for (std::size_t k = 0; k < m; ++k)
    for (std::size_t j = 0; j < n; ++j) {
      const int c = joint[k * n + j];
      if (c == 0) continue;  // 0 · log 0 = 0
      bits += c / total * std::log2(c * total / (static_cast<double>(py[k]) * pt[j]));
    }
  return bits;
}

Eigen::VectorXd single_mi_bits(const BinnedProblem& problem) {
  Eigen::VectorXd mi(problem.t_bins.cols());
  const auto samples = static_cast<std::size_t>(problem.samples);
  core::parallel_for(problem.t_bins.cols(), [&](std::ptrdiff_t j) {
    const std::span<const std::uint8_t> t(problem.t_bins.col(j).data(), samples);
    mi(j) = pair_mi_bits(problem.y_bins, problem.error_bins, t, problem.temperature_bins);
  });
  return mi;
}

double joint_mi_bits(const BinnedProblem& problem, std::span<const int> set,
                     std::span<const std::uint8_t> y_bins) {
  require_set(problem, set);
  if (y_bins.size() != static_cast<std::size_t>(problem.samples))
    throw core::DataError("placement: " + std::to_string(y_bins.size()) + " error bins for " +
                          std::to_string(problem.samples) + " samples");
  std::unordered_map<std::uint64_t, int> cells_t, cells_ty;
  cells_t.reserve(static_cast<std::size_t>(problem.samples));
  cells_ty.reserve(static_cast<std::size_t>(problem.samples));
  std::vector<int> py(static_cast<std::size_t>(problem.error_bins), 0);
  for (Eigen::Index s = 0; s < problem.samples; ++s) {
    const std::uint64_t key = cell_key(problem, set, s);
    const std::uint8_t y = y_bins[static_cast<std::size_t>(s)];
    ++cells_t[key];
    ++cells_ty[(key << 8) | y];
    ++py[y];
  }
  const double total = problem.samples;
  double bits = 0.0;
  // Summation order of an unordered_map is fixed for a given insertion sequence, which is the
  // sample order, so the sum does not depend on the thread that evaluates it.
  for (const auto& [key_ty, c] : cells_ty) {
    const int ct = cells_t.at(key_ty >> 8);
    const int cy = py[key_ty & 0xFF];
    bits += c / total * std::log2(c * total / (static_cast<double>(ct) * cy));
  }
  return bits;
}

double joint_mi_bits(const BinnedProblem& problem, std::span<const int> set) {
  return joint_mi_bits(problem, set, problem.y_bins);
}

double binned_entropy_bits(std::span<const std::uint8_t> bins, int bin_count) {
  std::vector<int> counts(static_cast<std::size_t>(bin_count), 0);
  for (std::uint8_t b : bins) ++counts[b];
  const double total = static_cast<double>(bins.size());
  double h = 0.0;
  for (int c : counts)
    if (c > 0) h -= c / total * std::log2(c / total);
  return h;
}

double singleton_share(const BinnedProblem& problem, std::span<const int> set) {
  require_set(problem, set);
  std::unordered_map<std::uint64_t, int> cells;
  cells.reserve(static_cast<std::size_t>(problem.samples));
  for (Eigen::Index s = 0; s < problem.samples; ++s) ++cells[cell_key(problem, set, s)];
  int alone = 0;
  for (const auto& [key, c] : cells)
    if (c == 1) ++alone;
  return static_cast<double>(alone) / problem.samples;
}

}  // namespace tt::placement
