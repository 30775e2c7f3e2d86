// A virtual test campaign: the same machine under other duty cycles and ambient conditions, run
// on one mesh with the operators assembled once; each run sampled at the named points (the
// sensors' readings) and at the tool (the thermal error), as a measurement would be.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "solvers/axis_error.hpp"
#include "solvers/thermal.hpp"

namespace tt::solvers {

struct CampaignRun {
  std::string name;
  std::string shape;  /// what kind of duty cycle it is, for reports
  core::CaseSpec spec;
};

/// At least eight runs of `hours` each (the standard's minimum is 5 h), derived from `base`:
/// P-1 extended, speed staircases up and down, irregular on/off cycles at several speeds (seeded
/// from `seed`), a run starting at a warmer uniform ambient, one whose ambient drifts, a
/// run-then-cool-down. The base case's own duty cycle is ignored; a feed axis that moves in the
/// base case reciprocates over its first stroke while the spindle runs (feed scaled with the
/// spindle speed) and stands while it stops.
std::vector<CampaignRun> campaign_runs(const core::CaseSpec& base, double hours,
                                       std::uint64_t seed);

/// Duty cycles for judging a reduced model against the full one, none of them used to build it:
/// the base case's own cycle (P-1 on SB-1, the feed-axis cycle on GM-1), a 6-hour staircase
/// (1000, 2000, 4000, 6000, 3000, 0 rpm, an hour each) and an 8-hour irregular cycle with at least
/// 15 switches (seeded from `seed`). A moving feed axis follows the spindle as in campaign_runs.
std::vector<CampaignRun> validation_runs(const core::CaseSpec& base, std::uint64_t seed);

struct CampaignResult {
  std::string name, shape;
  std::vector<double> times;          /// [s], t = 0 first
  Eigen::MatrixXd point_temperature;  /// #times x #named points [K]
  Eigen::MatrixXd node_temperature;   /// #times x #sampled nodes [K] (candidate sensors)
  Eigen::MatrixXd error;              /// #times x 9: thermal_error.csv's columns [m, rad]
  AxisError axis;  /// the error at the case's feed-axis points (no points when it names none)
};

/// Simulates every run on `mesh` (built from `base`; runs may differ from it only in duty cycle,
/// initial temperature and sinks). The thermal error at the tool and at the feed-axis points comes
/// from adjoint influence vectors (the twin's outputs on the full mesh, full_outputs).
/// Besides the named points, each run records the history at `sampled_nodes` (e.g. the surface
/// vertices that are candidate sensors).
std::vector<CampaignResult> simulate_campaign(const mesh::TetMesh& mesh, const core::CaseSpec& base,
                                              const std::vector<CampaignRun>& runs,
                                              const Progress& progress = {},
                                              const std::vector<int>& sampled_nodes = {});

}  // namespace tt::solvers
