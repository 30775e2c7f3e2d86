#include "fitting/residual_study.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <unsupported/Eigen/FFT>

#include "core/errors.hpp"
#include "core/rng.hpp"
#include "fitting/features.hpp"

namespace tt::fitting {

namespace {

/// The fits run in µm so that sums of squares stay far from underflow and cancellation.
constexpr double kMicrometres = 1e6;

/// Normal-equation pieces of one segment: [1 X]ᵀ[1 X], [1 X]ᵀy, yᵀy (y in µm).
struct Gram {
  Eigen::MatrixXd xx;
  Eigen::VectorXd xy;
  double yy = 0.0;
};

Gram gram_of(const Eigen::MatrixXd& x, const Eigen::VectorXd& y) {
  Eigen::MatrixXd a(x.rows(), x.cols() + 1);
  a.col(0).setOnes();
  a.rightCols(x.cols()) = x;
  return {a.transpose() * a, a.transpose() * y, y.squaredNorm()};
}

Eigen::VectorXd solved(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) {
  // A small relative ridge keeps nearly collinear temperatures solvable; it is far below the data.
  const double jitter = 1e-10 * std::max(1.0, a.diagonal().cwiseAbs().maxCoeff());
  const Eigen::MatrixXd regular = a + jitter * Eigen::MatrixXd::Identity(a.rows(), a.cols());
  return regular.ldlt().solve(b);
}

/// Leave-one-segment-out residual sum of squares [µm²] of each segment, from per-segment Grams.
Eigen::VectorXd heldout_rss_per_segment(const std::vector<Gram>& grams) {
  Gram total{Eigen::MatrixXd::Zero(grams[0].xx.rows(), grams[0].xx.cols()),
             Eigen::VectorXd::Zero(grams[0].xy.size()), 0.0};
  for (const auto& g : grams) {
    total.xx += g.xx;
    total.xy += g.xy;
  }
  Eigen::VectorXd rss(static_cast<Eigen::Index>(grams.size()));
  for (std::size_t k = 0; k < grams.size(); ++k) {
    const auto& g = grams[k];
    const Eigen::VectorXd beta = solved(total.xx - g.xx, total.xy - g.xy);
    rss(static_cast<Eigen::Index>(k)) =
        std::max(0.0, g.yy - 2.0 * beta.dot(g.xy) + beta.dot(g.xx * beta));
  }
  return rss;
}

/// Leave-one-segment-out residual sum of squares [µm²] from per-segment Grams.
double heldout_rss_of(const std::vector<Gram>& grams) {
  return heldout_rss_per_segment(grams).sum();
}

Eigen::VectorXd increment(const Segment& s, int sensor) {
  const auto t = s.group.temperature.col(sensor);
  return (t.array() - t(0)).matrix();
}

/// The regressors one term adds on a segment.
Eigen::MatrixXd term_columns(const EffectTerm& term, const std::vector<int>& sensors,
                             const Segment& s) {
  const Eigen::Index n = s.group.time.size();
  const Eigen::VectorXd krpm = s.speed / 1000.0;
  switch (term.kind) {
    case EffectKind::speed_dependent_offset: {
      Eigen::MatrixXd x(n, 2);
      x.col(0) = krpm;
      x.col(1) = krpm.array().square().matrix();
      return x;
    }
    case EffectKind::lagged_speed:
      return low_pass(s.group.time, krpm, term.time_constant);
    case EffectKind::lag: {
      Eigen::MatrixXd x(n, static_cast<Eigen::Index>(sensors.size()));
      for (std::size_t k = 0; k < sensors.size(); ++k)
        x.col(static_cast<Eigen::Index>(k)) =
            low_pass(s.group.time, increment(s, sensors[k]), term.time_constant);
      return x;
    }
    case EffectKind::ambient_temperature:
    case EffectKind::missing_sensor:
      return increment(s, term.sensor);
    case EffectKind::drift_in_time:
      return ((s.group.time.array() - s.group.time(0)) / 3600.0).matrix();
  }
  return Eigen::MatrixXd(n, 0);
}

Eigen::MatrixXd base_columns(const std::vector<int>& sensors, const Segment& s) {
  Eigen::MatrixXd x(s.group.time.size(), static_cast<Eigen::Index>(sensors.size()));
  for (std::size_t k = 0; k < sensors.size(); ++k)
    x.col(static_cast<Eigen::Index>(k)) = increment(s, sensors[k]);
  return x;
}

Eigen::MatrixXd joined_columns(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  Eigen::MatrixXd x(a.rows(), a.cols() + b.cols());
  x << a, b;
  return x;
}

Eigen::VectorXd target_um(const Segment& s, int target) {
  return s.group.error.col(target) * kMicrometres;
}

/// A surrogate of the columns of x with the same amplitude spectrum and random phases (the same
/// phases for every column, so the columns keep their cross-spectrum): same smoothness and power,
/// no timing relation to anything else.
Eigen::MatrixXd phase_randomised(const Eigen::MatrixXd& x, std::mt19937_64& rng) {
  const Eigen::Index n = x.rows();
  if (n < 4) return x;
  std::uniform_real_distribution<double> angle(0.0, 2.0 * std::numbers::pi);
  std::vector<std::complex<double>> rotation(static_cast<std::size_t>(n), 1.0);
  for (Eigen::Index k = 1; 2 * k < n; ++k) {
    rotation[static_cast<std::size_t>(k)] = std::polar(1.0, angle(rng));
    rotation[static_cast<std::size_t>(n - k)] = std::conj(rotation[static_cast<std::size_t>(k)]);
  }
  Eigen::FFT<double> fft;
  Eigen::MatrixXd out(n, x.cols());
  for (Eigen::Index c = 0; c < x.cols(); ++c) {
    std::vector<double> column(x.col(c).data(), x.col(c).data() + n);
    std::vector<std::complex<double>> spectrum;
    fft.fwd(spectrum, column);
    for (std::size_t k = 0; k < spectrum.size(); ++k) spectrum[k] *= rotation[k];
    std::vector<double> back;
    fft.inv(back, spectrum);
    for (Eigen::Index i = 0; i < n; ++i) out(i, c) = back[static_cast<std::size_t>(i)];
  }
  return out;
}

int parameter_count(const EffectTerm& term, const std::vector<int>& sensors) {
  switch (term.kind) {
    case EffectKind::speed_dependent_offset:
      return 2;
    case EffectKind::lag:
      return static_cast<int>(sensors.size());
    default:
      return 1;
  }
}

/// The settings tried for one kind; empty when the kind does not apply.
std::vector<EffectTerm> term_grid(EffectKind kind, const std::vector<int>& sensors,
                                  int sensor_count, const ResidualStudyOptions& options,
                                  bool has_speed) {
  std::vector<EffectTerm> grid;
  switch (kind) {
    case EffectKind::speed_dependent_offset:
      if (has_speed) grid.push_back({kind, 0.0, -1});
      break;
    case EffectKind::lagged_speed:
      if (has_speed)
        for (double tau : options.time_constants) grid.push_back({kind, tau, -1});
      break;
    case EffectKind::lag:
      for (double tau : options.time_constants) grid.push_back({kind, tau, -1});
      break;
    case EffectKind::ambient_temperature:
      if (options.ambient_sensor >= 0 &&
          std::find(sensors.begin(), sensors.end(), options.ambient_sensor) == sensors.end())
        grid.push_back({kind, 0.0, options.ambient_sensor});
      break;
    case EffectKind::missing_sensor:
      for (int c = 0; c < sensor_count; ++c)
        if (c != options.ambient_sensor &&
            std::find(sensors.begin(), sensors.end(), c) == sensors.end())
          grid.push_back({kind, 0.0, c});
      break;
    case EffectKind::drift_in_time:
      grid.push_back({kind, 0.0, -1});
      break;
  }
  return grid;
}

/// What the study keeps per segment while it tries terms: the current model's columns and y.
struct Workspace {
  std::vector<Eigen::MatrixXd> current;  /// per segment, the current model's regressors
  std::vector<Eigen::VectorXd> y;        /// per segment, the target [µm]
};

Eigen::VectorXd rss_per_segment_with(const Workspace& w,
                                     const std::vector<Eigen::MatrixXd>& extra) {
  std::vector<Gram> grams;
  for (std::size_t g = 0; g < w.y.size(); ++g)
    grams.push_back(gram_of(joined_columns(w.current[g], extra[g]), w.y[g]));
  return heldout_rss_per_segment(grams);
}

double rss_with(const Workspace& w, const std::vector<Eigen::MatrixXd>& extra) {
  return rss_per_segment_with(w, extra).sum();
}

/// Held-out RSS of each segment [µm²] with one term added to the workspace's model.
Eigen::VectorXd rss_per_segment_with_term(const EffectTerm& term, const std::vector<int>& sensors,
                                          const std::vector<Segment>& segments,
                                          const Workspace& w) {
  std::vector<Eigen::MatrixXd> extra;
  for (const auto& s : segments) extra.push_back(term_columns(term, sensors, s));
  return rss_per_segment_with(w, extra);
}

/// t statistic of the mean of per-segment gains (mean over its standard error); +inf when every
/// gain is equal and positive.
double gain_t(const Eigen::VectorXd& gains) {
  const auto k = static_cast<double>(gains.size());
  const double mean = gains.mean();
  if (gains.size() < 2) return mean > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  const double sd = std::sqrt((gains.array() - mean).square().sum() / (k - 1.0));
  if (!(sd > 0.0)) return mean > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  return mean / (sd / std::sqrt(k));
}

/// Per-segment held-out gains [µm²] of searching a grid of settings, nested: for segment k the
/// setting is the one of the lowest held-out RSS summed over the other segments, and k's gain is
/// its held-out RSS before less its held-out RSS with that setting. The search never sees k's
/// held-out residual, so picking the best of many settings (one more sensor among twenty) does not
/// show up as a gain on every segment.
Eigen::VectorXd nested_gains(const std::vector<EffectTerm>& grid, const std::vector<int>& sensors,
                             const std::vector<Segment>& segments, const Workspace& w,
                             const Eigen::VectorXd& before) {
  std::vector<Eigen::VectorXd> with;
  for (const auto& term : grid)
    with.push_back(rss_per_segment_with_term(term, sensors, segments, w));
  Eigen::VectorXd gains(before.size());
  for (Eigen::Index k = 0; k < before.size(); ++k) {
    std::size_t best = 0;
    for (std::size_t g = 1; g < with.size(); ++g)
      if (with[g].sum() - with[g](k) < with[best].sum() - with[best](k)) best = g;
    gains(k) = before(k) - with[best](k);
  }
  return gains;
}

/// The best term of a grid: its index and held-out RSS [m²]. With a surrogate stream, every
/// term's columns are replaced by phase-randomised surrogates (the same phases for every setting
/// of the grid, so the search over settings is repeated on one surrogate).
std::pair<int, double> best_of_grid(
    const std::vector<EffectTerm>& grid, const std::vector<int>& sensors,
    const std::vector<Segment>& segments, const Workspace& w,
    std::optional<std::pair<std::uint64_t, std::uint64_t>> surrogate = std::nullopt) {
  int best = -1;
  double best_rss = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < grid.size(); ++k) {
    std::vector<Eigen::MatrixXd> extra;
    std::optional<std::mt19937_64> rng;
    if (surrogate) rng = core::generator(surrogate->first, surrogate->second);
    for (std::size_t g = 0; g < segments.size(); ++g) {
      const Eigen::MatrixXd columns = term_columns(grid[k], sensors, segments[g]);
      extra.push_back(rng ? phase_randomised(columns, *rng) : columns);
    }
    const double rss = rss_with(w, extra);
    if (rss < best_rss) {
      best_rss = rss;
      best = static_cast<int>(k);
    }
  }
  return {best, best_rss / (kMicrometres * kMicrometres)};
}

Workspace workspace(const std::vector<Segment>& segments, int target,
                    const std::vector<int>& sensors, const std::vector<EffectTerm>& terms) {
  Workspace w;
  for (const auto& s : segments) {
    w.current.push_back(term_regressors(sensors, terms, s));
    w.y.push_back(target_um(s, target));
  }
  return w;
}

void require_segments(const std::vector<Segment>& segments, int target) {
  if (segments.empty()) throw core::DataError("no segments: expected at least one to fit on");
  std::vector<Group> groups = segment_groups(segments);
  require_consistent_groups(groups);
  for (const auto& s : segments)
    if (s.speed.size() != s.group.time.size())
      throw core::DataError("segment " + s.group.name + ": " + std::to_string(s.speed.size()) +
                            " speeds for " + std::to_string(s.group.time.size()) + " samples");
  const auto targets = static_cast<int>(segments.front().group.target_names.size());
  if (target < 0 || target >= targets)
    throw core::DataError("target " + std::to_string(target) + ": expected an index in [0, " +
                          std::to_string(targets) + ")");
}

}  // namespace

std::string effect_kind_name(EffectKind kind) {
  switch (kind) {
    case EffectKind::speed_dependent_offset:
      return "speed_dependent_offset";
    case EffectKind::lagged_speed:
      return "lagged_speed";
    case EffectKind::lag:
      return "lag";
    case EffectKind::ambient_temperature:
      return "ambient_temperature";
    case EffectKind::missing_sensor:
      return "missing_sensor";
    case EffectKind::drift_in_time:
      return "drift_in_time";
  }
  return "unknown";
}

Eigen::MatrixXd term_regressors(const std::vector<int>& sensors,
                                const std::vector<EffectTerm>& terms, const Segment& segment) {
  Eigen::MatrixXd x = base_columns(sensors, segment);
  for (const auto& term : terms) x = joined_columns(x, term_columns(term, sensors, segment));
  return x;
}

std::vector<std::string> term_regressor_names(const std::vector<int>& sensors,
                                              const std::vector<EffectTerm>& terms,
                                              const std::vector<std::string>& sensor_names) {
  const auto dt = [&](int c) { return "dT[" + sensor_names.at(static_cast<std::size_t>(c)) + "]"; };
  std::vector<std::string> names;
  for (int c : sensors) names.push_back(dt(c));
  for (const auto& term : terms) {
    const std::string lp =
        "lp" + std::to_string(static_cast<long>(std::lround(term.time_constant))) + "s(";
    switch (term.kind) {
      case EffectKind::speed_dependent_offset:
        names.push_back("speed_krpm");
        names.push_back("speed_krpm^2");
        break;
      case EffectKind::lagged_speed:
        names.push_back(lp + "speed_krpm)");
        break;
      case EffectKind::lag:
        for (int c : sensors) names.push_back(lp + dt(c) + ")");
        break;
      case EffectKind::ambient_temperature:
      case EffectKind::missing_sensor:
        names.push_back(dt(term.sensor));
        break;
      case EffectKind::drift_in_time:
        names.push_back("time_since_start_h");
        break;
    }
  }
  return names;
}

Eigen::VectorXd term_prediction(const TermModel& model, const Segment& segment) {
  return linear_prediction(model.fit, term_regressors(model.sensors, model.terms, segment));
}

TermModel fitted_term_model(const std::vector<Segment>& segments, int target,
                            const std::vector<int>& sensors, const std::vector<EffectTerm>& terms) {
  require_segments(segments, target);
  const Workspace w = workspace(segments, target, sensors, terms);
  Gram total = gram_of(w.current[0], w.y[0]);
  for (std::size_t g = 1; g < segments.size(); ++g) {
    const Gram next = gram_of(w.current[g], w.y[g]);
    total.xx += next.xx;
    total.xy += next.xy;
  }
  const Eigen::VectorXd beta = solved(total.xx, total.xy) / kMicrometres;
  TermModel model;
  model.target = target;
  model.sensors = sensors;
  model.terms = terms;
  model.fit.intercept = beta(0);
  model.fit.coefficients = beta.tail(beta.size() - 1);
  return model;
}

double heldout_rss(const std::vector<Segment>& segments, int target,
                   const std::vector<int>& sensors, const std::vector<EffectTerm>& terms) {
  require_segments(segments, target);
  if (segments.size() < 2)
    throw core::DataError("held-out residual on " + std::to_string(segments.size()) +
                          " segment: expected at least 2 training runs or segments");
  const Workspace w = workspace(segments, target, sensors, terms);
  std::vector<Gram> grams;
  for (std::size_t g = 0; g < segments.size(); ++g) grams.push_back(gram_of(w.current[g], w.y[g]));
  return heldout_rss_of(grams) / (kMicrometres * kMicrometres);
}

ChannelStudy residual_study(const std::vector<Segment>& training, int target,
                            const ResidualStudyOptions& options) {
  require_segments(training, target);
  if (training.size() < 2)
    throw core::DataError(
        "residual study on " + std::to_string(training.size()) +
        " training segment: expected at least 2, so that every term is judged on data it "
        "was not fitted on");
  const int sensor_count = static_cast<int>(training.front().group.sensor_names.size());
  bool has_speed = false;
  for (const auto& s : training) has_speed = has_speed || s.speed.cwiseAbs().maxCoeff() > 0.0;

  Eigen::Index rows = 0;
  for (const auto& s : training) rows += s.group.time.size();

  ChannelStudy study;
  study.target = target;
  study.target_name = training.front().group.target_names[static_cast<std::size_t>(target)];

  // 1. Baseline: forward selection of sensors on the held-out residual. The first sensor is taken
  //    even when it alone does not beat the intercept (a pair can when neither alone does); each
  //    further one must remove 1 %.
  std::vector<int> sensors;
  double rss = heldout_rss(training, target, sensors, {});
  while (static_cast<int>(sensors.size()) < std::min(options.max_sensors, sensor_count)) {
    int best = -1;
    double best_rss = std::numeric_limits<double>::infinity();
    for (int c = 0; c < sensor_count; ++c) {
      if (std::find(sensors.begin(), sensors.end(), c) != sensors.end()) continue;
      std::vector<int> trial = sensors;
      trial.push_back(c);
      const double r = heldout_rss(training, target, trial, {});
      if (r < best_rss) {
        best_rss = r;
        best = c;
      }
    }
    if (best < 0 || (!sensors.empty() && best_rss > 0.99 * rss)) break;
    sensors.push_back(best);
    rss = best_rss;
  }
  rss = heldout_rss(training, target, sensors, {});
  study.heldout_rss_before = rss;
  const double baseline_rss = rss;

  // 2. Greedy: add the term that removes the largest share of the held-out residual, if chance
  //    (phase-randomised surrogates of the same term, searched over the same settings) does not do
  //    as well.
  const std::vector<EffectKind> kinds{
      EffectKind::speed_dependent_offset, EffectKind::lagged_speed,   EffectKind::lag,
      EffectKind::ambient_temperature,    EffectKind::missing_sensor, EffectKind::drift_in_time};
  std::vector<EffectTerm> terms;
  std::vector<EffectKind> used;
  std::uint64_t stream = 0;
  for (int step = 0; step < options.max_effects && rss > 0.0; ++step) {
    const Workspace w = workspace(training, target, sensors, terms);
    std::vector<Effect> tested;
    std::vector<std::vector<EffectTerm>> grids;
    for (EffectKind kind : kinds) {
      if (std::find(used.begin(), used.end(), kind) != used.end()) continue;
      const auto grid = term_grid(kind, sensors, sensor_count, options, has_speed);
      if (grid.empty()) continue;
      const auto [best, best_rss] = best_of_grid(grid, sensors, training, w);
      Effect e;
      e.term = grid[static_cast<std::size_t>(best)];
      e.parameters = parameter_count(e.term, sensors);
      e.step_fraction = (rss - best_rss) / rss;
      e.explained_fraction = (rss - best_rss) / baseline_rss;
      e.null_fraction = std::numeric_limits<double>::quiet_NaN();
      tested.push_back(e);
      grids.push_back(grid);
    }
    std::vector<std::size_t> order(tested.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return tested[a].step_fraction > tested[b].step_fraction;
    });
    int claimed = -1;
    for (std::size_t rank = 0; rank < order.size() && rank < 3; ++rank) {
      Effect& e = tested[order[rank]];
      const double margin = e.step_fraction - options.penalty_per_parameter * e.parameters;
      if (margin <= 0.0) break;
      double null = -std::numeric_limits<double>::infinity();
      for (int draw = 0; draw < options.null_draws; ++draw) {
        const double null_rss = best_of_grid(grids[order[rank]], sensors, training, w,
                                             std::make_pair(options.seed, stream++))
                                    .second;
        null = std::max(null, (rss - null_rss) / rss);
      }
      // A share that no surrogate reaches is still no evidence when it is negative: the threshold
      // is never below zero.
      e.null_fraction = std::max(null, 0.0);
      // The gain must also hold from segment to segment, not come from one of them: the mean
      // per-segment held-out gain must exceed min_gain_t standard errors.
      std::vector<Eigen::MatrixXd> nothing;
      for (const auto& t : training) nothing.emplace_back(t.group.time.size(), 0);
      const Eigen::VectorXd before_rss = rss_per_segment_with(w, nothing);
      const Eigen::VectorXd with_rss = rss_per_segment_with_term(e.term, sensors, training, w);
      const Eigen::VectorXd gains =
          nested_gains(grids[order[rank]], sensors, training, w, before_rss);
      e.gain_t = gain_t(gains);
      e.segments_improved = static_cast<int>((gains.array() > 0.0).count());
      e.heldout_rms_before = std::sqrt(before_rss.sum() / static_cast<double>(rows)) / kMicrometres;
      e.heldout_rms_after = std::sqrt(with_rss.sum() / static_cast<double>(rows)) / kMicrometres;
      if (margin > e.null_fraction && e.gain_t > options.min_gain_t) {
        e.claimed = true;
        claimed = static_cast<int>(order[rank]);
        break;
      }
    }
    study.steps.emplace_back();
    for (std::size_t i : order) study.steps.back().push_back(tested[i]);
    if (claimed < 0) break;
    const Effect& e = tested[static_cast<std::size_t>(claimed)];
    study.effects.push_back(e);
    terms.push_back(e.term);
    used.push_back(e.term.kind);
    rss = heldout_rss(training, target, sensors, terms);
  }
  study.heldout_rss_after = rss;
  study.before = fitted_term_model(training, target, sensors, {});
  study.after = fitted_term_model(training, target, sensors, terms);
  return study;
}

}  // namespace tt::fitting
