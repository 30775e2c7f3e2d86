// The mutual information of patent CN101290266, formulas 1 and 2: equal-width bins over each
// series' own range, probabilities as counts over S, plug-in sums in bits. Joint histograms in
// m + 1 dimensions are held sparsely: a hash of the occupied cell tuples, never N^m cells.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <span>
#include <vector>

namespace tt::placement {

/// Bin index 0..bins-1 of each value, `bins` equal parts of [min, max]; the maximum falls in the
/// last bin. A constant series falls entirely in bin 0.
std::vector<std::uint8_t> equal_width_bins(const Eigen::VectorXd& values, int bins);

/// Candidate histories and the target, binned once.
struct BinnedProblem {
  int samples = 0;
  int temperature_bins = 0;  ///< N
  int error_bins = 0;        ///< M
  /// #samples x #candidates temperature bin indices, column-major (one history contiguous)
  Eigen::Matrix<std::uint8_t, Eigen::Dynamic, Eigen::Dynamic> t_bins;
  std::vector<std::uint8_t> y_bins;  ///< #samples error bin indices
};

/// temperatures: #samples x #candidates; error: #samples. Bins from 2 to 255.
BinnedProblem binned_problem(const Eigen::MatrixXd& temperatures, const Eigen::VectorXd& error,
                             int temperature_bins, int error_bins);

/// Formula 1 on a dense N x M table: I(Y;T) [bits] of two binned series of equal length.
double pair_mi_bits(std::span<const std::uint8_t> y_bins, int error_bins,
                    std::span<const std::uint8_t> t_bins, int temperature_bins);

/// Formula 1 for every candidate [bits], indexed like the columns.
Eigen::VectorXd single_mi_bits(const BinnedProblem& problem);

/// Formula 2: I(Y; T_i1..T_im) [bits] from the sparse (m+1)-dimensional histogram, for the
/// candidate columns in `set` (1 to 7 of them) and the error bins `y_bins` (the problem's own,
/// or a permutation of them for the shuffle test).
double joint_mi_bits(const BinnedProblem& problem, std::span<const int> set,
                     std::span<const std::uint8_t> y_bins);
/// Formula 2 with the problem's own error bins.
double joint_mi_bits(const BinnedProblem& problem, std::span<const int> set);

/// Plug-in entropy [bits] of binned values: the ceiling of every estimate above (I ≤ H(Y)).
double binned_entropy_bits(std::span<const std::uint8_t> bins, int bin_count);

/// Share of the samples that sit alone in their cell of the m-dimensional temperature histogram
/// of `set`: near 1 the joint estimate can no longer tell sensors apart.
double singleton_share(const BinnedProblem& problem, std::span<const int> set);

}  // namespace tt::placement
