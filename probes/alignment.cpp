#include "probes/alignment.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "core/errors.hpp"

namespace tt::probes {
namespace {

double entropy_term(double p) {
  return p > 0.0 ? -p * std::log(p) : 0.0;
}

std::string revolutions_text(double samples, double per_rev) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3g", samples / per_rev);
  return buf;
}

double pearson(const Eigen::Ref<const Eigen::VectorXd>& a,
               const Eigen::Ref<const Eigen::VectorXd>& b) {
  const Eigen::ArrayXd ca = a.array() - a.mean();
  const Eigen::ArrayXd cb = b.array() - b.mean();
  const double den = std::sqrt((ca * ca).sum() * (cb * cb).sum());
  return den > 0.0 ? (ca * cb).sum() / den : 0.0;
}

}  // namespace

std::string method_name(AlignmentMethod method) {
  return std::string(core::name_in(kAlignmentMethodNames, method));
}

AlignmentPlan alignment_plan(const ProbeRecord& record, const AlignmentOptions& options) {
  if (record.readings.empty())
    throw core::DataError("probe record has no readings: at least one reading is needed");
  if (!(record.speed_rev_per_s > 0.0) || !(record.sample_rate_hz > 0.0))
    throw core::DataError("probe record: speed " + std::to_string(record.speed_rev_per_s * 60.0) +
                          " rpm and sample rate " + std::to_string(record.sample_rate_hz) +
                          " Hz must both be > 0");
  AlignmentPlan plan;
  const double per_rev = record.samples_per_revolution();
  plan.samples_per_revolution = per_rev;
  const int columns = static_cast<int>(record.readings.front().samples_m.cols());
  for (int p : options.probes)
    if (p < 0 || p >= columns)
      throw core::DataError("alignment probe column " + std::to_string(p) + ": must be in [0, " +
                            std::to_string(columns) + ") (S1 is column 0)");
  if (options.probes.empty())
    throw core::DataError("alignment probes: empty list; give at least one probe column");
  plan.probes = options.probes;

  for (std::size_t i = 0; i < record.readings.size(); ++i) {
    const Reading& r = record.readings[i];
    if (r.samples_m.cols() != columns)
      throw core::DataError("reading " + std::to_string(i + 1) + " has " +
                            std::to_string(r.samples_m.cols()) + " probe columns, the first has " +
                            std::to_string(columns));
    if (static_cast<double>(r.samples_m.rows()) <= per_rev)
      throw core::DataError(
          "reading " + std::to_string(i + 1) + " has " + std::to_string(r.samples_m.rows()) +
          " samples = " + revolutions_text(static_cast<double>(r.samples_m.rows()), per_rev) +
          " revolutions: every reading must cover more than one revolution (> " +
          std::to_string(per_rev) +
          " samples) so that it contains the reference angle; record "
          "longer readings or check speed and sample rate");
  }
  if (!(options.window_revolutions > 0.0 && options.window_revolutions <= 1.0))
    throw core::DataError("window_revolutions = " + std::to_string(options.window_revolutions) +
                          ": must be in (0, 1]; a whole revolution (1) is the robust choice");
  // M <= n always holds because every reading is longer than one revolution.
  plan.window_samples =
      std::max<Eigen::Index>(4, std::lround(options.window_revolutions * per_rev));
  plan.window_samples = std::min(plan.window_samples, record.readings.front().samples_m.rows());
  // One revolution plus a margin on both sides, so that every angle has an equivalent offset
  // with neighbours for the sub-sample parabola (offsets k and k + P are the same angle).
  plan.offsets = static_cast<Eigen::Index>(std::ceil(per_rev)) + 3;
  plan.require_positive_correlation = options.require_positive_correlation;

  if (options.level_revolutions < 0.0)
    throw core::DataError("level_revolutions = " + std::to_string(options.level_revolutions) +
                          ": must be >= 0 (0 takes the single sample at the reference angle)");
  plan.level_samples = std::clamp<Eigen::Index>(std::lround(options.level_revolutions * per_rev), 1,
                                                plan.window_samples);
  if (options.bins != 0 && options.bins < 2)
    throw core::DataError("bins = " + std::to_string(options.bins) + ": must be >= 2 (0 picks it)");
  plan.bins = options.bins != 0
                  ? options.bins
                  : std::max(4, static_cast<int>(std::lround(
                                    2.0 * std::cbrt(static_cast<double>(plan.window_samples)))));
  return plan;
}

double information_distance(const Eigen::Ref<const Eigen::VectorXd>& a,
                            const Eigen::Ref<const Eigen::VectorXd>& b, int bins) {
  if (a.size() != b.size() || a.size() == 0)
    throw core::DataError("information_distance: windows of " + std::to_string(a.size()) + " and " +
                          std::to_string(b.size()) + " samples; need equal, non-empty");
  if (bins < 2)
    throw core::DataError("information_distance: bins = " + std::to_string(bins) +
                          ": must be >= 2");
  const Eigen::ArrayXd ca = a.array() - a.mean();
  const Eigen::ArrayXd cb = b.array() - b.mean();
  const double lo = std::min(ca.minCoeff(), cb.minCoeff());
  const double hi = std::max(ca.maxCoeff(), cb.maxCoeff());
  if (!(hi > lo)) return 0.0;
  const double scale = (bins - 1) / (hi - lo);

  // Linear binning: a value between grid points k and k+1 adds (1−f, f) to them.
  Eigen::MatrixXd joint = Eigen::MatrixXd::Zero(bins, bins);
  auto split = [&](double v, int& k, double& f) {
    const double u = std::clamp((v - lo) * scale, 0.0, static_cast<double>(bins - 1));
    k = std::min(static_cast<int>(u), bins - 2);
    f = u - k;
  };
  for (Eigen::Index j = 0; j < ca.size(); ++j) {
    int ka = 0, kb = 0;
    double fa = 0.0, fb = 0.0;
    split(ca(j), ka, fa);
    split(cb(j), kb, fb);
    joint(ka, kb) += (1 - fa) * (1 - fb);
    joint(ka + 1, kb) += fa * (1 - fb);
    joint(ka, kb + 1) += (1 - fa) * fb;
    joint(ka + 1, kb + 1) += fa * fb;
  }
  joint /= static_cast<double>(ca.size());
  const Eigen::VectorXd pa = joint.rowwise().sum();
  const Eigen::VectorXd pb = joint.colwise().sum().transpose();
  double h_joint = 0.0, h_a = 0.0, h_b = 0.0;
  for (Eigen::Index i = 0; i < joint.size(); ++i) h_joint += entropy_term(joint.data()[i]);
  for (int k = 0; k < bins; ++k) {
    h_a += entropy_term(pa(k));
    h_b += entropy_term(pb(k));
  }
  // D = H(A,B) − I(A;B) with I = H(A) + H(B) − H(A,B); clamp rounding below zero.
  return std::max(0.0, 2.0 * h_joint - h_a - h_b);
}

Eigen::MatrixXd periodic_extension(const Eigen::MatrixXd& samples, double samples_per_revolution,
                                   Eigen::Index rows) {
  const Eigen::Index n = samples.rows();
  if (!(static_cast<double>(n) > samples_per_revolution) || !(samples_per_revolution > 0.0))
    throw core::DataError("periodic_extension: " + std::to_string(n) + " samples with " +
                          std::to_string(samples_per_revolution) +
                          " per revolution; the reading must cover more than one revolution");
  Eigen::MatrixXd out(rows, samples.cols());
  const Eigen::Index copied = std::min(rows, n);
  out.topRows(copied) = samples.topRows(copied);
  for (Eigen::Index q = n; q < rows; ++q) {
    double t = static_cast<double>(q);
    while (t > static_cast<double>(n - 1)) t -= samples_per_revolution;
    t = std::max(t, 0.0);
    const auto k = std::min(static_cast<Eigen::Index>(t), n - 2);
    const double f = t - static_cast<double>(k);
    out.row(q) = (1.0 - f) * samples.row(k) + f * samples.row(k + 1);
  }
  return out;
}

std::vector<double> alignment_scores(const Eigen::MatrixXd& reference,
                                     const Eigen::MatrixXd& extended, const AlignmentPlan& plan,
                                     AlignmentMethod method) {
  const Eigen::Index m = plan.window_samples;
  if (reference.rows() != m || extended.rows() < m + plan.offsets)
    throw core::DataError("alignment_scores: reference of " + std::to_string(reference.rows()) +
                          " rows and reading of " + std::to_string(extended.rows()) +
                          " rows do not fit a window of " + std::to_string(m) + " and " +
                          std::to_string(plan.offsets) + " offsets");
  std::vector<double> scores(static_cast<std::size_t>(plan.offsets), 0.0);
  for (Eigen::Index k = 0; k < plan.offsets; ++k) {
    double distance = 0.0, correlation = 0.0;
    for (int p : plan.probes) {
      const auto ref = reference.col(p);
      const auto cand = extended.col(p).segment(k, m);
      correlation += pearson(ref, cand);
      if (method == AlignmentMethod::information_distance)
        distance += information_distance(ref, cand, plan.bins);
    }
    if (method != AlignmentMethod::information_distance)
      scores[static_cast<std::size_t>(k)] = -correlation;
    else if (plan.require_positive_correlation && !(correlation > 0.0))
      scores[static_cast<std::size_t>(k)] = std::numeric_limits<double>::infinity();
    else
      scores[static_cast<std::size_t>(k)] = distance;
  }
  return scores;
}

ReadingAlignment refined_alignment(const std::vector<double>& scores,
                                   double samples_per_revolution) {
  if (scores.size() < 3) throw core::DataError("refined_alignment: fewer than 3 candidate offsets");
  // Interior minimum only: scores cover more than a turn, so an end minimum recurs inside.
  const auto best = static_cast<std::size_t>(
      std::min_element(scores.begin() + 1, scores.end() - 1) - scores.begin());
  ReadingAlignment out;
  out.best_score = scores[best];
  out.offset_samples = static_cast<double>(best);
  if (std::isfinite(scores[best - 1]) && std::isfinite(scores[best + 1])) {
    const double curvature = scores[best - 1] - 2.0 * scores[best] + scores[best + 1];
    if (curvature > 0.0)
      out.offset_samples +=
          std::clamp(0.5 * (scores[best - 1] - scores[best + 1]) / curvature, -0.5, 0.5);
  }
  // The runner-up must be a different angle, not a neighbour of the minimum (mod one turn).
  out.runner_up_score = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < scores.size(); ++k) {
    const double d = std::fmod(std::abs(static_cast<double>(k) - static_cast<double>(best)),
                               samples_per_revolution);
    if (std::min(d, samples_per_revolution - d) > samples_per_revolution / 8.0)
      out.runner_up_score = std::min(out.runner_up_score, scores[k]);
  }
  return out;
}

std::vector<ReadingAlignment> record_alignment(const ProbeRecord& record, const AlignmentPlan& plan,
                                               AlignmentMethod method) {
  std::vector<ReadingAlignment> out(record.readings.size());
  if (method == AlignmentMethod::none || method == AlignmentMethod::revolution_mean) return out;
  const Eigen::MatrixXd reference = record.readings.front().samples_m.topRows(plan.window_samples);
  const Eigen::Index rows = plan.offsets + plan.window_samples + 1;
  for (std::size_t i = 0; i < record.readings.size(); ++i) {
    if (i == 0) {
      // The reference angle is by definition sample 0 of the first reading.
      out[i].runner_up_score = std::numeric_limits<double>::infinity();
      continue;
    }
    const Eigen::MatrixXd extended =
        periodic_extension(record.readings[i].samples_m, plan.samples_per_revolution, rows);
    out[i] = refined_alignment(alignment_scores(reference, extended, plan, method),
                               plan.samples_per_revolution);
  }
  return out;
}

}  // namespace tt::probes
