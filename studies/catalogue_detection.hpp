// Placement for detection on the calibration catalogue's effects: where the changes `calibrate`
// would look for (a heat input on any patch of the surface, a film, a source's growth with its
// temperature, a conductivity or heat capacity, the air) would show at a sensor, each at a stated
// size, beside the observer's own unknown inputs (studies::observer_detection_problem). A
// generator's effect is drawn from the catalogue's kinds at random places; an observer's unknown
// input acts only where the case declares a load.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calibration/effects.hpp"
#include "core/case_spec.hpp"
#include "mesh/tet_mesh.hpp"
#include "placement/detection.hpp"
#include "solvers/thermal.hpp"

namespace tt::studies {

/// The sizes at which each kind of the catalogue's effects is asked to be seen.
struct CatalogueSizes {
  /// A heat input's power on its patch [W] (under the speed law, at the reference speed).
  double heat_w = 5;
  /// A film's change, or its growth with speed at the reference speed, as a share of its
  /// declared coefficient [-].
  double film_share = 0.25;
  double source_coefficient_per_k = 0.02;  ///< a source's heat growing with its temperature [1/K]
  double material_change = 0.1;  ///< relative change of a conductivity or a heat capacity [-]
  double air_k = 1;              ///< the air's offset over the whole run [K]
};

/// Where the candidates are and how their readings are judged.
struct CatalogueDetectionInput {
  std::vector<std::string> names;       ///< #candidates
  std::vector<Eigen::Vector3d> points;  ///< #candidates [m]
  double sensor_sigma_k = 0.05;         ///< white noise of every reading [K]
  double sample_s = 300;                ///< the runs read every sample_s
  double sustain_s = 900;               ///< held this long (solvers::ConsistencyOptions)
  CatalogueSizes sizes;
  /// The catalogue's patches and laws (patch_spacing, patch_half_size, heat_laws).
  calibration::CalibrationOptions catalogue;
  /// March the full model instead of the reduced one on the candidates' rows (what `calibrate
  /// --full` does; the reduced one keeps the response at the candidates, and is faster).
  bool full_order = false;
};

/// The catalogue's effects as placement for detection sees them.
struct CatalogueDetection {
  placement::DetectionProblem problem;
  std::vector<calibration::Effect> effects;  ///< #effects: what each is and where it acts
  Eigen::VectorXd sizes;                     ///< #effects: its parameter's size (detection_size)
};

/// Each heat-flow candidate of the catalogue on `declared` (calibration::heat_flow_candidates,
/// marched on the reduced model whose basis holds the candidates' rows, or in full order) along
/// `runs` (cases with `declared`'s operators, e.g. the campaign's fitting runs), held at its kind's
/// size: how far it moves each candidate's reading for the sustain time, in sigmas; each kind
/// (kind_name) weighted to count once (placement::weights_per_kind), as a generator draws a kind,
/// then its place. `progress` gets the simulated time over the runs' total. Throws DataError for no
/// run, a candidate outside the mesh or sustain_s not > 0, SolverError for sample_s not > 0
/// (reading_times).
CatalogueDetection catalogue_detection(const mesh::TetMesh& mesh, const core::CaseSpec& declared,
                                       const std::vector<core::CaseSpec>& runs,
                                       const CatalogueDetectionInput& input,
                                       const solvers::Progress& progress = {});

/// The size of candidate `c`'s (one) parameter at which placement for detection asks to see it,
/// from `sizes` and the declared films; 0 for a kind it does not ask about (the sensors' own
/// effects, expansion).
double detection_size(const calibration::Candidate& c, const core::CaseSpec& declared,
                      const CatalogueSizes& sizes);

}  // namespace tt::studies
