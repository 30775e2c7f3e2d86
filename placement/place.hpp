// One call that runs every placement method on candidate histories and error targets:
// the patent's histogram mutual information (ranking, exhaustive or genetic search, with its
// saturation diagnosis), the stronger criteria (Gaussian MI greedy and GA, KSG greedy, JMI on
// KSG, QR pivoting on POD modes), the baselines (correlation ranking, grey relational grade) and,
// when the input carries the observer's covariance model, placement for estimation (the physics
// observer's posterior variance of each target).
//
// Data flow: histories on any time grid -> resampled to S samples -> per target: binned and
// linear problems -> one Selection per (method, m).
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/enum_names.hpp"
#include "core/ids.hpp"
#include "placement/estimation.hpp"
#include "placement/gaussian.hpp"
#include "placement/saturation.hpp"
#include "placement/search.hpp"

namespace tt::placement {

enum class Method {
  kHistogramMi,     ///< patent CN101290266: formula 1 ranking, formula 2 with exhaustive/GA search
  kGaussianGreedy,  ///< forward selection on R² (−½·log2(1 − R²) bits)
  kGaussianGa,      ///< the patent's search with the Gaussian MI as fitness
  kKsgGreedy,       ///< forward selection on the KSG joint I(Y; T_S)
  kJmiKsg,          ///< joint mutual information on 2-D KSG terms
  kQrPod,           ///< column-pivoted QR on the leading POD modes (ignores the target)
  kCorrelation,     ///< DB3401/T 326-2024 7.1: rank by |r| with the error
  kGreyRelational,  ///< grey relational grade, ρ = grey_rho
  kObserverVariance,  ///< greedy on the observer's mean posterior variance (needs `estimation`)
};

/// Stable lower-case names used in files, in the order all_methods() lists them.
inline constexpr std::array<core::Named<Method>, 9> kMethodNames{{
    {Method::kHistogramMi, "histogram_mi"},
    {Method::kGaussianGreedy, "gaussian_greedy"},
    {Method::kGaussianGa, "gaussian_ga"},
    {Method::kKsgGreedy, "ksg_greedy"},
    {Method::kJmiKsg, "jmi_ksg"},
    {Method::kQrPod, "qr_pod"},
    {Method::kCorrelation, "correlation"},
    {Method::kGreyRelational, "grey_relational"},
    {Method::kObserverVariance, "observer_variance"},
}};
static_assert(core::one_to_one(kMethodNames));

/// The method's name in kMethodNames.
std::string_view method_name(Method method);
std::vector<Method> all_methods();

/// One error component at the TCP, on its own (SB-1: "dy" and "dz").
struct Target {
  std::string name;
  Eigen::VectorXd values_m;  ///< #times error [m]
};

struct PlacementInput {
  std::vector<core::SensorId> ids;  ///< #candidates, distinct
  Eigen::MatrixX3d positions_m;     ///< #candidates x 3 [m]
  Eigen::VectorXd times_s;          ///< #times, strictly increasing [s]
  Eigen::MatrixXd temperatures_K;   ///< #times x #candidates histories [K]
  std::vector<Target> targets;
  /// The physics observer's covariance model on these candidates (rows in column order) and
  /// targets (rows in target order), for Method::kObserverVariance; without it that method is
  /// skipped. It does not see the histories.
  std::optional<EstimationProblem> estimation;
};

struct PlacementOptions {
  int samples = 100;          ///< S; 0 uses the input samples as they are
  int temperature_bins = 20;  ///< N
  int error_bins = 20;        ///< M
  int m_max = 6;              ///< sets for m = 1..m_max (the histogram method stops at 7)
  std::uint64_t seed = 1;     ///< master seed of every random draw
  std::int64_t exhaustive_limit = 30000;  ///< search exhaustively when C(pool, m) <= this
  GaOptions ga;  ///< its seed is derived from `seed` per target, method and m
  SaturationOptions saturation;
  int ksg_k = 4;  ///< neighbours of the KSG estimator (3 to 5)
  /// Beyond this pool size KSG and JMI see a subsample: the half with the largest |r| with the
  /// target plus the other half spread evenly over the rest of the pool.
  int ksg_max_candidates = 300;
  Collinearity collinearity;  ///< when a candidate does not count as a sensor of its own
  bool mirror_twins = true;   ///< drop the higher member of each mirror pair from the searches
  double mirror_plane_x_m = 0.0;
  double mirror_tolerance_m = 1e-6;
  double grey_rho = 0.5;
  std::vector<Method> methods = all_methods();
  /// Gets a line as each target's method that took progress_after_s or more is done ("dy:
  /// observer_variance, m = 1..20, 24.1 s"): a long placement (the GA, observer_variance on a
  /// large twin) is not silent, a quick one does not fill the screen.
  std::function<void(const std::string&)> progress;
  double progress_after_s = 1;
};

/// The set one method gives for one m.
struct Selection {
  Method method = Method::kHistogramMi;
  std::string search;  ///< "ranking", "exhaustive", "ga", "greedy" or "qr"
  int m = 0;
  std::vector<core::SensorId> ids;  ///< chosen, in the order the method chose them
  std::vector<int> columns;         ///< the same as input columns
  double score = 0.0;               ///< the method's own criterion, see score_kind
  std::string score_kind;           ///< "histogram_bits", "gaussian_bits", "ksg_bits", "abs_r",
                                    ///< "grey_grade", "posterior_sigma_m"
  double gaussian_bits = 0.0;  ///< −½·log2(1 − R²) of the set: one yardstick for all methods
  double seconds = 0.0;        ///< wall time to produce this set [s]
  std::int64_t evaluations = 0;                   ///< distinct combinations scored (searches only)
  std::optional<SaturationDiagnosis> saturation;  ///< histogram method only
};

struct TargetResult {
  std::string target;
  Eigen::VectorXd mi_bits;    ///< #candidates formula-1 I(Y; T_i) [bits]
  std::vector<int> mi_rank;   ///< #candidates 1-based rank by mi_bits, ties to the lower column
  std::vector<int> ksg_pool;  ///< columns KSG and JMI chose from (depends on the target)
  std::vector<Selection> selections;
};

struct PlacementResult {
  std::vector<core::SensorId> ids;  ///< as in the input
  Eigen::MatrixX3d positions_m;
  Eigen::VectorXd sample_times_s;          ///< the S times the histories were resampled to
  std::vector<std::pair<int, int>> twins;  ///< (kept, dropped) column pairs
  std::vector<int> pool;                   ///< columns the searches choose from
  std::vector<int> ksg_pool;               ///< columns KSG and JMI choose from
  double pod_seconds = 0.0;                ///< time of the POD, shared by the qr_pod sets
  PlacementOptions options;                ///< as used, for the record
  std::vector<TargetResult> targets;
};

/// Runs every method in options.methods for every target. Throws core::DataError on
/// inconsistent input (sizes, non-finite values, duplicate ids) or options.
PlacementResult place_all(const PlacementInput& input, const PlacementOptions& options);

}  // namespace tt::placement
