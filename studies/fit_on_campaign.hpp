// fit CASE's pipeline: how well a thermal-error model fed by m sensors predicts the drift on duty
// cycles it was not fitted on (DB3401/T 326-2024 metrics S, S_M, S_sigma). SI units throughout
// ([m], [s], [K]); io/fit_campaign_out writes fit.json, the modelling record, compensation.csv,
// the sensor-count tables and the held-out groups' readings.
// 1. The virtual campaign's runs as groups with sensor noise on every reading (seeded from the
//    case), split into fitting, validation and test runs by name.
// 2. Placement on the fitting groups only (with the campaign's reduced model, placement for
//    estimation too, on the fitting runs' duty cycles).
// 3. Per TCP target: model, settings and placement method chosen on validation, refitted, tested;
//    the test S_M by number of sensors; with the network, its own figures beside the choice.
// 4. On a case with feed-axis points: models of the error at those points and the axis polynomial
//    fitted from their predictions (studies/axis_fit.hpp).
#pragma once

#include <optional>
#include <vector>

#include "core/case_spec.hpp"
#include "fitting/group.hpp"
#include "fitting/selection.hpp"
#include "solvers/campaign.hpp"
#include "solvers/twin.hpp"
#include "studies/axis_fit.hpp"
#include "studies/network_candidate.hpp"
#include "studies/progress.hpp"

namespace tt::studies {

struct CampaignFitOptions {
  /// least squares only (no model search)
  bool quick = false;
  /// also try the CNN-BiGRU-attention network (seed 004)
  bool network = false;
  /// the accuracy asked for: the sensor-count tables' smallest m with test S_M below it [m]
  double required_sm = 1e-6;
  /// The reduced model the campaign ran on and the campaign's runs (the results' order): with
  /// both, placement for estimation (observer_variance, the physics observer's posterior
  /// variance over the fitting runs' duty cycles) is one more placement method; nullptr: not.
  const solvers::Twin* twin = nullptr;
  const std::vector<solvers::CampaignRun>* runs = nullptr;
  /// a line per stage of the long work (placement for estimation's duty cycles); empty: none
  Progress progress;
};

/// One TCP target's choice, tested.
struct CampaignTargetFit {
  fitting::Evaluation evaluation;
  /// the test S_M per placement method and number of sensors
  fitting::SensorCountTable sensor_count;
  /// mean over the test groups of the drift's standard deviation [m]
  double uncompensated_std = 0.0;
  /// the network's own figures (with the network, when a network candidate was fitted)
  std::optional<NetworkFigures> network;
};

struct CampaignFitReport {
  /// one per campaign run, with sensor noise: the TCP's targets, then the axis points' errors
  std::vector<fitting::Group> groups;
  fitting::Split split;
  std::vector<CampaignTargetFit> targets;
  std::optional<AxisFit> axis;
  /// wall time of the feed axis's step [s]
  double axis_seconds = 0.0;

  std::vector<fitting::Evaluation> evaluations() const;
};

/// The study on the campaign's results (solvers::campaign_runs of the case, simulated). Throws
/// core::DataError when the campaign lacks the runs a role names, or its groups disagree.
CampaignFitReport fit_on_campaign(const core::CaseSpec& spec,
                                  const std::vector<solvers::CampaignResult>& results,
                                  const CampaignFitOptions& options);

}  // namespace tt::studies
