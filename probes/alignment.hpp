// Finding the reference angle in every reading of a spindle without orientation (patent
// CN101628396 step 4): the first reading's window of M samples is the reference; in a later
// reading the offset whose M samples minimise the information distance
//   D(S1, S2) = H(S1, S2) − I(S1; S2) = 2·H(S1, S2) − H(S1) − H(S2)
// marks the sample taken at the reference angle. Cross-correlation is provided as a baseline.
// Design choices (why) are in docs/probes.md, "Alignment".
#pragma once

#include <string>
#include <vector>

#include "core/enum_names.hpp"
#include "probes/record.hpp"

namespace tt::probes {

/// How the sample at the reference angle is found in a reading.
enum class AlignmentMethod {
  information_distance,  ///< the patent's method
  cross_correlation,     ///< maximum Pearson correlation of the mean-free windows
  none,                  ///< first sample of each reading, whatever angle it was taken at
  revolution_mean,       ///< no angle at all: the mean over whole revolutions
};

/// Short names used in file names and reports.
inline constexpr std::array<core::Named<AlignmentMethod>, 4> kAlignmentMethodNames{{
    {AlignmentMethod::information_distance, "info"},
    {AlignmentMethod::cross_correlation, "xcorr"},
    {AlignmentMethod::none, "noalign"},
    {AlignmentMethod::revolution_mean, "revmean"},
}};
static_assert(core::one_to_one(kAlignmentMethodNames));

/// The method's name in kAlignmentMethodNames.
std::string method_name(AlignmentMethod method);

struct AlignmentOptions {
  /// Reference window M in revolutions, in (0, 1]. A whole revolution makes the window's
  /// values a non-monotone function of angle, which the information distance needs to tell
  /// offsets apart (on a monotone stretch every offset is a bijection of the reference).
  double window_revolutions = 1.0;
  /// Histogram bins per probe; 0 picks them from M (about M^(1/3) · 2, at least 4).
  int bins = 0;
  /// Arc averaged for the reading at the reference angle [revolutions]; 0 takes the single
  /// (interpolated) sample at the reference angle, as the patent does.
  double level_revolutions = 0.125;
  /// Probe columns whose windows enter the alignment score (summed over the probes).
  std::vector<int> probes = {s1_y1, s2_y2, s3_x1, s4_x2};
  /// Information distance only: search only offsets where the windows correlate positively.
  /// D is blind to the direction of a relation, so without this a profile with a symmetry (pure
  /// eccentricity: p(θ + π) = −p(θ)) matches just as well half a turn away.
  bool require_positive_correlation = true;
};

/// Window, level arc and bins resolved for one record.
struct AlignmentPlan {
  double samples_per_revolution = 0.0;
  /// M, the reference window length
  Eigen::Index window_samples = 0;
  /// Number of candidate offsets searched in each reading: one revolution and a margin
  Eigen::Index offsets = 0;
  /// L, the arc averaged for the level at the reference angle
  Eigen::Index level_samples = 1;
  int bins = 0;
  std::vector<int> probes;
  bool require_positive_correlation = true;
};

/// The plan for a record; throws DataError naming the reading when one is not longer than a
/// revolution, and when options are out of range.
AlignmentPlan alignment_plan(const ProbeRecord& record, const AlignmentOptions& options);

/// Information distance [nats] between two equally long windows. Each window has its own mean
/// removed (drift shifts the level, not the shape), both are binned on one common grid of
/// `bins` points spanning the union of their ranges, with linear (two-bin) weights so that the
/// distance varies continuously with the data and the offset can be refined between samples.
/// The price of linear binning: a window's distance to itself is not 0 but a floor set by the
/// binning (about 1.4 nats for 12 bins); a copy shifted by a constant has exactly that floor.
double information_distance(const Eigen::Ref<const Eigen::VectorXd>& a,
                            const Eigen::Ref<const Eigen::VectorXd>& b, int bins);

/// `rows` samples of a reading continued past its end by its own periodicity: sample q >= n is
/// the (interpolated) sample at q − P, P = samples per revolution. A reading longer than one
/// revolution thus holds a full window at every angle. #rows x #probes [m]
Eigen::MatrixXd periodic_extension(const Eigen::MatrixXd& samples, double samples_per_revolution,
                                   Eigen::Index rows);

/// Score of every candidate offset k = 0 .. plan.offsets−1 of `extended` (a reading's
/// periodic_extension) against the `reference` window (M x #probes, the first M samples of
/// the first reading); lower is better. information_distance: Σ over plan.probes of D, +inf
/// where the windows correlate negatively if so planned; cross_correlation: −Σ Pearson r.
std::vector<double> alignment_scores(const Eigen::MatrixXd& reference,
                                     const Eigen::MatrixXd& extended, const AlignmentPlan& plan,
                                     AlignmentMethod method);

struct ReadingAlignment {
  /// Fractional sample index of the reference angle within the reading
  double offset_samples = 0.0;
  double best_score = 0.0;
  /// Best score more than 1/8 revolution away from the minimum; close to best_score means an
  /// ambiguous alignment (e.g. a pure eccentricity looks alike half a turn away).
  double runner_up_score = 0.0;
};

/// The minimum of `scores` over the interior offsets (scores span more than a turn, so the
/// same angle recurs inside), refined to a fraction of a sample by a parabola through the
/// minimum and its neighbours.
ReadingAlignment refined_alignment(const std::vector<double>& scores,
                                   double samples_per_revolution);

/// Alignment of every reading of the record (the first one is the reference, offset 0).
std::vector<ReadingAlignment> record_alignment(const ProbeRecord& record, const AlignmentPlan& plan,
                                               AlignmentMethod method);

}  // namespace tt::probes
