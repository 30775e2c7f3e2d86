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
#include "core/units.hpp"
#include "fitting/features.hpp"

namespace tt::fitting {

namespace {

/// The fits run in µm so that sums of squares stay far from underflow and cancellation.
using core::kMicrometresPerMetre;

/// How the baseline's form fits: with an intercept or not, and its ridge strength (linear_fit's
/// λ, dimensionless).
struct Form {
  bool intercept = true;
  double lambda = 0.0;
};

Form form_of(const Baseline& b) {
  const bool ridge = b.spec.kind == ModelKind::ridge || b.spec.kind == ModelKind::distributed_lag;
  return {b.spec.kind != ModelKind::no_compensation, ridge ? b.spec.ridge_lambda : 0.0};
}

/// Normal-equation pieces of one segment: AᵀA, Aᵀy, yᵀy with A = [1 X] (or X with no intercept),
/// y in µm.
struct Gram {
  Eigen::MatrixXd xx;
  Eigen::VectorXd xy;
  double yy = 0.0;
};

Gram gram_of(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const Form& form) {
  const Eigen::Index first = form.intercept ? 1 : 0;
  Eigen::MatrixXd a(x.rows(), x.cols() + first);
  if (form.intercept) a.col(0).setOnes();
  a.rightCols(x.cols()) = x;
  return {a.transpose() * a, a.transpose() * y, y.squaredNorm()};
}

/// The coefficients minimising linear_fit's objective from the normal matrix `a` of the fitting
/// rows: λ times each regressor's centred sum of squares (its row count when the column is
/// constant) on the diagonal, the intercept (column 0) not shrunk. The system is scaled to a unit
/// diagonal, so temperatures in K and a speed in rpm are treated alike, and a relative ridge far
/// below the data keeps nearly collinear columns solvable.
Eigen::VectorXd solved(Eigen::MatrixXd a, const Eigen::VectorXd& b, const Form& form) {
  if (a.rows() == 0) return Eigen::VectorXd(0);
  if (form.intercept && form.lambda > 0.0) {
    const double n = a(0, 0);
    for (Eigen::Index j = 1; j < a.rows(); ++j) {
      const double centred = a(j, j) - a(0, j) * a(0, j) / n;
      a(j, j) += form.lambda * (centred > 0.0 ? centred : n);
    }
  }
  Eigen::VectorXd scale = a.diagonal().cwiseAbs().cwiseSqrt();
  for (Eigen::Index j = 0; j < scale.size(); ++j)
    if (!(scale(j) > 0.0)) scale(j) = 1.0;
  const Eigen::VectorXd inverse = scale.cwiseInverse();
  Eigen::MatrixXd unit = inverse.asDiagonal() * a * inverse.asDiagonal();
  unit.diagonal().array() += 1e-10;
  return inverse.asDiagonal() * unit.ldlt().solve(inverse.asDiagonal() * b);
}

/// Leave-one-segment-out residual sum of squares [µm²] of each segment, from per-segment Grams.
Eigen::VectorXd heldout_rss_per_segment(const std::vector<Gram>& grams, const Form& form) {
  Gram total{Eigen::MatrixXd::Zero(grams[0].xx.rows(), grams[0].xx.cols()),
             Eigen::VectorXd::Zero(grams[0].xy.size()), 0.0};
  for (const auto& g : grams) {
    total.xx += g.xx;
    total.xy += g.xy;
  }
  Eigen::VectorXd rss(static_cast<Eigen::Index>(grams.size()));
  for (std::size_t k = 0; k < grams.size(); ++k) {
    const auto& g = grams[k];
    const Eigen::VectorXd beta = solved(total.xx - g.xx, total.xy - g.xy, form);
    rss(static_cast<Eigen::Index>(k)) =
        std::max(0.0, g.yy - 2.0 * beta.dot(g.xy) + beta.dot(g.xx * beta));
  }
  return rss;
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
    case TermKind::speed_dependent_offset: {
      Eigen::MatrixXd x(n, 2);
      x.col(0) = krpm;
      x.col(1) = krpm.array().square().matrix();
      return x;
    }
    case TermKind::lagged_speed:
      return low_pass(s.group.time, krpm, term.time_constant);
    case TermKind::lag: {
      Eigen::MatrixXd x(n, static_cast<Eigen::Index>(sensors.size()));
      for (std::size_t k = 0; k < sensors.size(); ++k)
        x.col(static_cast<Eigen::Index>(k)) =
            low_pass(s.group.time, increment(s, sensors[k]), term.time_constant);
      return x;
    }
    case TermKind::ambient_temperature:
    case TermKind::missing_sensor:
      return increment(s, term.sensor);
    case TermKind::drift_in_time:
      return ((s.group.time.array() - s.group.time(0)) / 3600.0).matrix();
  }
  return Eigen::MatrixXd(n, 0);
}

Eigen::MatrixXd base_columns(const Baseline& baseline, const Segment& s) {
  if (baseline.spec.kind == ModelKind::no_compensation)
    return Eigen::MatrixXd(s.group.time.size(), 0);
  return feature_matrix(baseline.features, s.group);
}

Eigen::MatrixXd joined_columns(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  Eigen::MatrixXd x(a.rows(), a.cols() + b.cols());
  x << a, b;
  return x;
}

Eigen::VectorXd target_um(const Segment& s, int target) {
  return s.group.error.col(target) * kMicrometresPerMetre;
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
    case TermKind::speed_dependent_offset:
      return 2;
    case TermKind::lag:
      return static_cast<int>(sensors.size());
    default:
      return 1;
  }
}

/// The settings tried for one kind; empty when the kind does not apply.
std::vector<EffectTerm> term_grid(TermKind kind, const std::vector<int>& sensors, int sensor_count,
                                  const ResidualStudyOptions& options, bool has_speed) {
  std::vector<EffectTerm> grid;
  switch (kind) {
    case TermKind::speed_dependent_offset:
      if (has_speed) grid.push_back({kind, 0.0, -1});
      break;
    case TermKind::lagged_speed:
      if (has_speed)
        for (double tau : options.time_constants) grid.push_back({kind, tau, -1});
      break;
    case TermKind::lag:
      // A lag filters the baseline's sensors: none to filter on no compensation.
      if (!sensors.empty())
        for (double tau : options.time_constants) grid.push_back({kind, tau, -1});
      break;
    case TermKind::ambient_temperature:
      if (options.ambient_sensor >= 0 &&
          std::find(sensors.begin(), sensors.end(), options.ambient_sensor) == sensors.end())
        grid.push_back({kind, 0.0, options.ambient_sensor});
      break;
    case TermKind::missing_sensor:
      for (int c = 0; c < sensor_count; ++c)
        if (c != options.ambient_sensor &&
            std::find(sensors.begin(), sensors.end(), c) == sensors.end())
          grid.push_back({kind, 0.0, c});
      break;
    case TermKind::drift_in_time:
      grid.push_back({kind, 0.0, -1});
      break;
  }
  return grid;
}

/// What the study keeps per segment while it tries terms: the current model's columns and y.
struct Workspace {
  std::vector<Eigen::MatrixXd> current;  /// per segment, the current model's regressors
  std::vector<Eigen::VectorXd> y;        /// per segment, the target [µm]
  Form form;
};

Eigen::VectorXd rss_per_segment_with(const Workspace& w,
                                     const std::vector<Eigen::MatrixXd>& extra) {
  std::vector<Gram> grams;
  for (std::size_t g = 0; g < w.y.size(); ++g)
    grams.push_back(gram_of(joined_columns(w.current[g], extra[g]), w.y[g], w.form));
  return heldout_rss_per_segment(grams, w.form);
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
  return {best, best_rss / (kMicrometresPerMetre * kMicrometresPerMetre)};
}

Workspace workspace(const std::vector<Segment>& segments, int target, const Baseline& baseline,
                    const std::vector<EffectTerm>& terms) {
  Workspace w;
  w.form = form_of(baseline);
  for (const auto& s : segments) {
    w.current.push_back(term_regressors(baseline, terms, s));
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

std::string term_kind_name(TermKind kind) {
  return std::string(core::name_in(kTermKindNames, kind));
}

Baseline baseline_of(const FittedModel& model) {
  switch (model.spec.kind) {
    case ModelKind::no_compensation:
      return {model.spec, FeatureMap{}};
    case ModelKind::least_squares:
    case ModelKind::ridge:
    case ModelKind::distributed_lag:
      return {model.spec, model.features};
    default:
      break;
  }
  throw core::DataError("residual study from a '" + model_label(model.spec) +
                        "' model: expected a model linear in its regressors (least squares, "
                        "ridge, distributed lag) or no compensation");
}

Baseline least_squares_baseline(const std::vector<int>& sensors,
                                const std::vector<std::string>& sensor_names) {
  Baseline b;
  b.spec.kind = ModelKind::least_squares;
  b.spec.reject_gross_errors = false;
  b.features.sensors = sensors;
  for (int c : sensors)
    b.features.sensor_names.push_back(sensor_names.at(static_cast<std::size_t>(c)));
  return b;
}

const std::vector<int>& baseline_sensors(const Baseline& baseline) {
  return baseline.features.sensors;
}

Eigen::MatrixXd term_regressors(const Baseline& baseline, const std::vector<EffectTerm>& terms,
                                const Segment& segment) {
  Eigen::MatrixXd x = base_columns(baseline, segment);
  for (const auto& term : terms)
    x = joined_columns(x, term_columns(term, baseline_sensors(baseline), segment));
  return x;
}

std::vector<std::string> term_regressor_names(const Baseline& baseline,
                                              const std::vector<EffectTerm>& terms,
                                              const std::vector<std::string>& sensor_names) {
  const auto dt = [&](int c) { return "dT[" + sensor_names.at(static_cast<std::size_t>(c)) + "]"; };
  std::vector<std::string> names;
  if (baseline.spec.kind != ModelKind::no_compensation) names = feature_names(baseline.features);
  for (const auto& term : terms) {
    const std::string lp =
        "lp" + std::to_string(static_cast<long>(std::lround(term.time_constant))) + "s(";
    switch (term.kind) {
      case TermKind::speed_dependent_offset:
        names.push_back("speed_krpm");
        names.push_back("speed_krpm^2");
        break;
      case TermKind::lagged_speed:
        names.push_back(lp + "speed_krpm)");
        break;
      case TermKind::lag:
        for (int c : baseline_sensors(baseline)) names.push_back(lp + dt(c) + ")");
        break;
      case TermKind::ambient_temperature:
      case TermKind::missing_sensor:
        names.push_back(dt(term.sensor));
        break;
      case TermKind::drift_in_time:
        names.push_back("time_since_start_h");
        break;
    }
  }
  return names;
}

Eigen::VectorXd term_prediction(const TermModel& model, const Segment& segment) {
  return linear_prediction(model.fit, term_regressors(model.baseline, model.terms, segment));
}

TermModel fitted_term_model(const std::vector<Segment>& segments, int target,
                            const Baseline& baseline, const std::vector<EffectTerm>& terms) {
  require_segments(segments, target);
  TermModel model;
  model.target = target;
  model.baseline = baseline;
  model.terms = terms;
  const bool none = baseline.spec.kind == ModelKind::no_compensation;
  if (terms.empty() && none) {
    model.fit = LinearFit{0.0, Eigen::VectorXd(0)};
    return model;
  }
  if (terms.empty()) {
    // The baseline alone is fitted as the model choice fits it (the 3σ criterion included).
    const FittedModel fitted =
        fitted_model(baseline.spec, segment_groups(segments), baseline_sensors(baseline), target);
    model.fit = std::get<LinearFit>(fitted.body);
    return model;
  }
  const Workspace w = workspace(segments, target, baseline, terms);
  Gram total = gram_of(w.current[0], w.y[0], w.form);
  for (std::size_t g = 1; g < segments.size(); ++g) {
    const Gram next = gram_of(w.current[g], w.y[g], w.form);
    total.xx += next.xx;
    total.xy += next.xy;
  }
  const Eigen::VectorXd beta = solved(total.xx, total.xy, w.form) / kMicrometresPerMetre;
  const Eigen::Index first = w.form.intercept ? 1 : 0;
  model.fit.intercept = w.form.intercept ? beta(0) : 0.0;
  model.fit.coefficients = beta.tail(beta.size() - first);
  return model;
}

double heldout_rss(const std::vector<Segment>& segments, int target, const Baseline& baseline,
                   const std::vector<EffectTerm>& terms) {
  require_segments(segments, target);
  if (segments.size() < 2)
    throw core::DataError("held-out residual on " + std::to_string(segments.size()) +
                          " segment: expected at least 2 training runs or segments");
  const Workspace w = workspace(segments, target, baseline, terms);
  std::vector<Gram> grams;
  for (std::size_t g = 0; g < segments.size(); ++g)
    grams.push_back(gram_of(w.current[g], w.y[g], w.form));
  return heldout_rss_per_segment(grams, w.form).sum() /
         (kMicrometresPerMetre * kMicrometresPerMetre);
}

namespace {

/// The best setting of every kind not yet used, as an untested effect, with the grid searched.
struct Candidates {
  std::vector<Effect> tested;
  std::vector<std::vector<EffectTerm>> grids;
};

/// One greedy step's candidates on the workspace `w` whose held-out RSS is `rss` (`baseline_rss`
/// the baseline's).
Candidates step_candidates(const std::vector<TermKind>& used, const std::vector<int>& sensors,
                           int sensor_count, bool has_speed, const std::vector<Segment>& training,
                           const Workspace& w, double rss, double baseline_rss,
                           const ResidualStudyOptions& options) {
  const std::vector<TermKind> kinds{
      TermKind::speed_dependent_offset, TermKind::lagged_speed,   TermKind::lag,
      TermKind::ambient_temperature,    TermKind::missing_sensor, TermKind::drift_in_time};
  Candidates c;
  for (TermKind kind : kinds) {
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
    c.tested.push_back(e);
    c.grids.push_back(grid);
  }
  return c;
}

/// Judges one candidate against chance and across segments: its null share from `null_draws`
/// surrogate searches over its grid (surrogate streams taken from `stream` on), its per-segment
/// gain t and held-out RMS before and after [m] over the `rows` training samples. Whether it is
/// claimed (its margin beyond the parameter penalty, `margin`, exceeds the null and the gain t
/// exceeds min_gain_t).
bool claimed_effect(Effect& e, double margin, const std::vector<EffectTerm>& grid,
                    const std::vector<int>& sensors, const std::vector<Segment>& training,
                    const Workspace& w, double rss, Eigen::Index rows,
                    const ResidualStudyOptions& options, std::uint64_t& stream) {
  double null = -std::numeric_limits<double>::infinity();
  for (int draw = 0; draw < options.null_draws; ++draw) {
    const double null_rss =
        best_of_grid(grid, sensors, training, w, std::make_pair(options.seed, stream++)).second;
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
  const Eigen::VectorXd gains = nested_gains(grid, sensors, training, w, before_rss);
  e.gain_t = gain_t(gains);
  e.segments_improved = static_cast<int>((gains.array() > 0.0).count());
  e.heldout_rms_before =
      std::sqrt(before_rss.sum() / static_cast<double>(rows)) / kMicrometresPerMetre;
  e.heldout_rms_after =
      std::sqrt(with_rss.sum() / static_cast<double>(rows)) / kMicrometresPerMetre;
  return margin > e.null_fraction && e.gain_t > options.min_gain_t;
}

}  // namespace

ChannelStudy residual_study(const std::vector<Segment>& training, int target,
                            const Baseline& baseline, const ResidualStudyOptions& options) {
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

  // 1. The baseline's held-out residual, each segment predicted by the baseline fitted on the
  //    others.
  const std::vector<int>& sensors = baseline_sensors(baseline);
  double rss = heldout_rss(training, target, baseline, {});
  study.heldout_rss_before = rss;
  const double baseline_rss = rss;

  // 2. Greedy: add the term that removes the largest share of the held-out residual, if chance
  //    (phase-randomised surrogates of the same term, searched over the same settings) does not do
  //    as well.
  std::vector<EffectTerm> terms;
  std::vector<TermKind> used;
  std::uint64_t stream = 0;
  for (int step = 0; step < options.max_effects && rss > 0.0; ++step) {
    const Workspace w = workspace(training, target, baseline, terms);
    Candidates c = step_candidates(used, sensors, sensor_count, has_speed, training, w, rss,
                                   baseline_rss, options);
    std::vector<Effect>& tested = c.tested;
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
      if (claimed_effect(e, margin, c.grids[order[rank]], sensors, training, w, rss, rows, options,
                         stream)) {
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
    rss = heldout_rss(training, target, baseline, terms);
  }
  study.heldout_rss_after = rss;
  study.before = fitted_term_model(training, target, baseline, {});
  study.after = terms.empty() ? study.before : fitted_term_model(training, target, baseline, terms);
  return study;
}

}  // namespace tt::fitting
