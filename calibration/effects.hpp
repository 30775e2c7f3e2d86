// Candidate effects that the declared model may miss, each with the FEM response of every channel
// to a unit of its parameters, and the choice among them: fitted by least squares across the
// training runs, scored on runs held out from the fit, claimed only above what noise gives.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "calibration/model.hpp"
#include "core/case_spec.hpp"
#include "core/enum_names.hpp"
#include "mesh/tet_mesh.hpp"

namespace tt::calibration {

enum class EffectKind {
  ambient_temperature,
  heat_input,
  speed_dependent_convection,
  temperature_dependent_heat,
  boundary_conductance,
  material_parameter,
  sensor_offset,
  sensor_lag
};
/// The kinds' names in calibration.json and reports.
inline constexpr std::array<core::Named<EffectKind>, 8> kEffectKindNames{{
    {EffectKind::ambient_temperature, "ambient_temperature"},
    {EffectKind::heat_input, "heat_input"},
    {EffectKind::speed_dependent_convection, "speed_dependent_convection"},
    {EffectKind::temperature_dependent_heat, "temperature_dependent_heat"},
    {EffectKind::boundary_conductance, "boundary_conductance"},
    {EffectKind::material_parameter, "material_parameter"},
    {EffectKind::sensor_offset, "sensor_offset"},
    {EffectKind::sensor_lag, "sensor_lag"},
}};
static_assert(core::one_to_one(kEffectKindNames));

/// The kind's name in kEffectKindNames.
std::string kind_name(EffectKind kind);

/// How a heat input's flux follows the spindle: in proportion to speed, or constant.
enum class HeatLaw { speed, constant };
/// The laws' names in calibration.json and candidate names.
inline constexpr std::array<core::Named<HeatLaw>, 2> kHeatLawNames{{
    {HeatLaw::speed, "speed"},
    {HeatLaw::constant, "constant"},
}};
static_assert(core::one_to_one(kHeatLawNames));
/// The law's name in kHeatLawNames.
std::string law_name(HeatLaw law);

struct CalibrationOptions {
  double patch_spacing = 0.10;     /// grid of candidate heat-input patch centres [m]
  double patch_half_size = 0.065;  /// half edge of a patch's box [m]
  /// The laws a heat input on a patch is tried under (one candidate per patch and law).
  std::vector<HeatLaw> heat_laws{HeatLaw::speed, HeatLaw::constant};
  /// Place of a heat input refined after the grid: `heat_refine_levels` grids, each a third of
  /// the previous spacing, of boxes `heat_refine_half_scale` x patch_half_size around the best
  /// `heat_refine_parents` places found so far.
  int heat_refine_levels = 2, heat_refine_parents = 3;
  double heat_refine_half_scale = 0.6;
  double ambient_knot_interval = 1800;  /// hat functions of the air temperature [s]
  std::vector<double> lag_grid_s{30, 60, 120, 200, 300, 450, 700, 1000};
  /// Exponents of a claimed film's growth with speed tried besides 1 (forced convection's film
  /// grows with about the 0.5th to 0.8th power of the flow speed): the law is chosen by its
  /// held-out score like any candidate. Empty: exponent 1 only.
  std::vector<double> speed_exponent_grid{0.5, 0.6, 0.7, 0.8, 0.9, 1.2};
  int lag_refine_steps = 16;  /// geometric steps between the grid neighbours of a claimed lag
  double ridge = 1e-8;        /// relative to the normal matrix's mean diagonal
  double penalty_per_parameter = 2;          /// complexity penalty [whitened sum of squares]
  double temperature_tolerance_K = 0.025;    /// model-form error not to be explained by an effect
  double displacement_tolerance_rel = 0.02;  /// ... relative to a probe's simulated RMS excursion
  double displacement_tolerance_m = 0.1e-6;  /// ... plus this [m]
  double noise_floor_K = 0.005, noise_floor_m = 0.01e-6;  /// least noise assumed per channel
  int null_trials = 10;                                   /// fits to pure noise for the threshold
  int max_effects = 3;
  /// Sweeps of backfitting after the one-after-the-other choice: each claim chosen again with
  /// the other claims' fits removed from the training residual, until no claim changes.
  int backfit_sweeps = 3;
  /// Candidates of the first round reported (best per kind and place): the several-places
  /// candidates and the pairs' pool need more than the eight that one place each gave.
  int ranking_size = 12;
  /// Pairs scored jointly (max_effects >= 2): among the `pair_pool` best physical candidates of
  /// the first round (a per-run air among them), at most `pair_pool_per_kind` of a kind.
  int pair_pool = 8, pair_pool_per_kind = 3;
  /// ... and each of the first `pair_partner_searches` pool members with its best partner of each
  /// kind over the whole catalogue, every candidate fitted jointly with the member (one joint
  /// least squares per candidate each).
  int pair_partner_searches = 8;
  std::uint64_t seed = 20260107;
  // What a fitted parameter may be (docs/calibration.md, "Physics within bounds"): a candidate
  // that needs a value outside these to fit is reported as unphysical and never claimed.
  /// A per-run air temperature is the shop's: at most this far from the declared sink [K] ...
  double air_range_K = 5;
  /// ... changing at most this fast between knots [K/h] (a run's ambient sensor overrides both).
  double air_rate_K_per_h = 3;
  /// |correlation| of a fitted air with the run's speed (both averaged over the knots' hats,
  /// centred per run) from which the air is taken for a speed mechanism's shadow, not the shop's.
  double air_duty_correlation = 0.7;
  /// Relative change of a conductivity, heat capacity or expansion coefficient: a factor of at
  /// most 1.5 either way.
  double material_change_min = -1.0 / 3, material_change_max = 0.5;
  /// Temperature coefficient of a heat source after the change [1/K].
  double temperature_coefficient_min_per_K = -0.05, temperature_coefficient_max_per_K = 0.15;
  // Refit of the claims about the updated model (docs/calibration.md, "Refit"): Gauss–Newton on
  // the claims' shared parameters, each step one march per training run; it stops when every
  // parameter moves by less than `refit_tolerance_sigmas` of its standard error (or by less than
  // `refit_tolerance_rel` of its value), at most `refit_max_iterations` steps (0: off,
  // `calibrate --case --no-refit`). The refitted sizes are kept only where they predict each
  // training run, fitted on the others, better than the claims as chosen (the held-out check).
  int refit_max_iterations = 8;
  int resize_pool = 4;  /// candidates select_effects sizes about their update at most
  double refit_tolerance_sigmas = 0.05, refit_tolerance_rel = 1e-3;
};

/// One run reduced to what the fit needs.
struct RunModel {
  std::string name;
  core::CaseSpec spec;       /// the declared case under this run's inputs
  Eigen::VectorXd times;     /// #samples [s]
  Eigen::MatrixXd base;      /// #samples x #channels: declared model [K | m]
  Eigen::MatrixXd measured;  /// #samples x #channels [K | m], NaN missing
  Eigen::VectorXd air;       /// #samples: the run's ambient sensor [K], NaN missing; empty: none
};

/// The material value a material_parameter candidate changes.
enum class MaterialField { conductivity, heat_capacity, expansion };
/// The fields' names in calibration.json and candidate names.
inline constexpr std::array<core::Named<MaterialField>, 3> kMaterialFieldNames{{
    {MaterialField::conductivity, "conductivity"},
    {MaterialField::heat_capacity, "heat_capacity"},
    {MaterialField::expansion, "expansion"},
}};
static_assert(core::one_to_one(kMaterialFieldNames));
/// The field's name in kMaterialFieldNames.
std::string field_name(MaterialField field);
/// The value of `m` that `field` changes: conductivity [W/(m K)], specific heat [J/(kg K)] (the
/// heat capacity's relative change at a fixed density), expansion [1/K].
double& material_value(core::Material& m, MaterialField field);

// Where and how each kind of effect acts: one alternative per EffectKind (in its order), holding
// indices into the declared case (convection entries, heat sources, boundary groups, bodies,
// materials) or into the readout (sensors). Names are the edge's business (io/).

/// The air: hat functions at `knots` on the sinks of `entries` (convection entries).
struct AmbientTemperature {
  std::vector<int> entries;
  std::vector<double> knots;  /// [s]
};
/// Heat through a patch of the surface: the faces of `groups` (boundary groups) bounding `body`
/// whose centroids lie in the box.
struct HeatInput {
  HeatLaw law = HeatLaw::constant;
  double ref_speed_rpm = 0;  /// law speed: the flux is the parameter times speed / ref_speed_rpm
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  /// area-weighted face centroid [m]
  double area = 0;                                   /// [m^2]
  std::vector<int> groups;
  int body = -1;  /// -1: every body the groups bound
};
/// Films (convection entries `entries`) whose coefficient grows with speed: each entry's gain
/// changes by the parameter times its weight (1 for a single place; its declared h for one share
/// of h everywhere), following (speed / ref_speed_rpm)^speed_exponent.
struct SpeedDependentConvection {
  std::vector<int> entries;
  std::vector<double> weights;
  double ref_speed_rpm = 0, speed_exponent = 1;
};
/// Heat of the sources `sources` growing with their temperature: each coefficient [1/K] changes
/// by the parameter times its weight.
struct TemperatureDependentHeat {
  std::vector<int> sources;
  std::vector<double> weights;
};
/// Films (convection entries `entries`) whose h changes by the parameter times its weight
/// [W/(m^2 K)].
struct BoundaryConductance {
  std::vector<int> entries;
  std::vector<double> weights;
};
/// A relative change of one value of material `material`.
struct MaterialParameter {
  int material = -1;
  MaterialField field = MaterialField::conductivity;
};
/// A constant added to sensor `sensor`'s reading [K].
struct SensorOffset {
  int sensor = -1;
};
/// A first-order lag of sensor `sensor`'s reading.
struct SensorLag {
  int sensor = -1;
  double time_constant_s = 0;
};
using Effect =
    std::variant<AmbientTemperature, HeatInput, SpeedDependentConvection, TemperatureDependentHeat,
                 BoundaryConductance, MaterialParameter, SensorOffset, SensorLag>;
static_assert(std::variant_size_v<Effect> == kEffectKindNames.size());
static_assert(
    std::is_same_v<std::variant_alternative_t<static_cast<size_t>(EffectKind::sensor_lag), Effect>,
                   SensorLag>);
static_assert(
    std::is_same_v<
        std::variant_alternative_t<static_cast<size_t>(EffectKind::material_parameter), Effect>,
        MaterialParameter>);

/// The kind an effect's alternative is.
inline EffectKind kind(const Effect& e) {
  return static_cast<EffectKind>(e.index());
}

/// A candidate effect: what it is and where it acts, and its channel responses per run.
struct Candidate {
  std::string name;
  Effect effect = HeatInput{};
  std::vector<std::string> parameters;  /// names with units
  bool per_run = false;                 /// parameters fitted run by run (an unknown signal)
  bool fixed = false;                   /// one column whose amplitude is 1 (a lag filter)
  std::vector<Eigen::MatrixXd>
      columns;  /// per run: (#samples #channels) x #parameters (column-major channels)
  /// A one-parameter candidate's unit loads: their responses times `unit_weights` (separable
  /// first, then loads) sum to its column. Kept so that the column can be marched again about an
  /// updated model (refit_claimed). Empty for the air, the sensors' own effects and expansion,
  /// whose columns are not loads of the thermal march.
  std::vector<SeparableColumn> unit_separable;
  std::vector<LoadColumn> unit_loads;
  std::vector<double> unit_weights;
};
inline EffectKind kind(const Candidate& c) {
  return kind(c.effect);
}
/// Whether `c` changes a material's expansion (its readout's change is exact: no march).
bool changes_expansion(const Candidate& c);
/// The sensor `c` acts on (offset, lag); -1 for other kinds.
int sensor_of(const Candidate& c);
/// Whether `a` and `b` are of one kind and act at one place (a heat input under either law, a
/// sensor's lag at any time constant): the ranking keeps the best of each.
bool same_place(const Candidate& a, const Candidate& b);

/// Channel histories of the declared model for each run and the catalogue of candidate effects
/// with their responses (one march per run with every unit load as a column).
struct Catalogue {
  Readout readout;
  std::vector<RunModel> runs;
  std::vector<Candidate> candidates;
};

/// Heat-input patches: boxes on a grid over the exterior faces (centroid inside the box), one
/// patch per boundary group and body the box covers (heat into the bore wall is not heat into the
/// shaft across the gap).
struct Patch {
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  /// area-weighted face centroid [m]
  double area = 0;                                   /// [m^2]
  std::vector<int> faces;
  std::vector<int> groups;  /// boundary groups the faces belong to
  int body = -1;            /// the body the faces bound
};
std::vector<Patch> surface_patches(const mesh::TetMesh& mesh, double spacing, double half_size);
/// #nodes integral of the shape functions over faces [m^2].
Eigen::VectorXd face_load(const mesh::TetMesh& mesh, const std::vector<int>& faces);

/// Builds the catalogue: `runs` carry the measured channels (order of `r`). `ambient_only`
/// restricts the candidates to the air temperature (for runs held for testing). The responses
/// come from marches of `model` (full or reduced order); `progress` gets the simulated time over
/// the runs' total.
Catalogue catalogue(const MarchModel& model, const core::CaseSpec& declared, const Readout& r,
                    const std::vector<io::MeasuredRun>& runs, const CalibrationOptions& options,
                    bool ambient_only = false, const solvers::Progress& progress = {});

/// The catalogue's candidates that change the heat flow (the air on every sink and on the
/// unfixed groups' sinks, heat inputs on patches, films, sources' growth with temperature,
/// conductivity and capacity, in several places where the catalogue has them; not the sensors'
/// own effects nor expansion), their columns the responses at `r`'s temperature channels along
/// each of `runs` (cases with `declared`'s operators under their own duty cycles) read at
/// `times` (one vector per run). What placement for detection asks to see.
std::vector<Candidate> heat_flow_candidates(const MarchModel& model, const core::CaseSpec& declared,
                                            const Readout& r,
                                            const std::vector<core::CaseSpec>& runs,
                                            const std::vector<Eigen::VectorXd>& times,
                                            const CalibrationOptions& options,
                                            const solvers::Progress& progress = {});

/// `cat` with lag candidates of `sensor` at `lag_refine_steps` time constants spaced
/// geometrically between the grid values either side of `tau` [s]: the grid's step (up to 1.7x)
/// leaves much of a lag's signal unexplained.
Catalogue with_refined_lag(const Catalogue& cat, int sensor, double tau,
                           const CalibrationOptions& options);

/// `cat` with copies of its speed-dependent convection candidate `candidate` whose gain follows
/// speed to each power of options.speed_exponent_grid, marched like the catalogue's own (one march
/// per run): a film's law of speed is not known, and exponent 1 sized to its in-sample optimum
/// misses runs with other speeds.
Catalogue with_speed_exponents(const MarchModel& model, const Catalogue& cat, int candidate,
                               const CalibrationOptions& options);

/// A candidate fitted to the training residual.
struct EffectFit {
  int candidate = -1;
  EffectKind kind = EffectKind::heat_input;
  std::string name;
  std::vector<double> parameters;                   /// shared parameters
  std::vector<std::vector<double>> run_parameters;  /// per run (per-run candidates)
  double heldout_gain = 0;         /// whitened sum of squares removed on held-out runs
  double score = 0;                /// heldout_gain - penalty
  double explained_fraction = 0;   /// share of the training residual's whitened SS removed alone
  double floor = 0;                /// model-form allowance for this candidate
  std::vector<double> fold_gains;  /// held-out gain per training run (sums to heldout_gain)
  std::string unphysical;          /// why the fitted parameters are not physical; empty: they are
  double duty_correlation = 0;     /// per-run air: correlation of the fitted air with the speed
  // Refit about the updated model (refit_claimed); iterations 0: not refitted.
  std::vector<double> linearised;  /// the shared parameters as the linearised fit gave them
  int refit_iterations = 0;        /// Gauss–Newton steps taken
  bool refit_converged = false;    /// stopped by the rule, not by the iteration cap
  /// Whitened training sum of squares of the updated model at the linearised and at the refitted
  /// parameters (all claims together).
  double refit_ss_linearised = 0, refit_ss = 0;
  /// The refit's held-out check (refit_claimed): summed over the training runs, the whitened sum
  /// of squares on each run of the claims fitted on the others, linearised and refitted. The
  /// refitted parameters are kept only when they are lower (`refit_accepted`); otherwise the
  /// claims keep the parameters they were chosen with.
  bool refit_heldout_checked = false, refit_accepted = true;
  std::vector<double> refitted;  /// the refitted shared parameters, kept or not
  double refit_heldout_ss_linearised = 0, refit_heldout_ss_refitted = 0;
};

/// Two candidates of different kinds whose scores differ by less than the spread of their
/// per-run held-out gains: neither is claimed.
struct Ambiguity {
  EffectFit first, second;  /// best, and best of another kind
  double difference = 0;    /// first.score - second.score
  double spread = 0;        /// sqrt(#runs) x standard deviation of the per-run gain differences
  int channel = -1;         /// channel on which their fitted responses differ most (in sigmas)
  double channel_difference = 0;  /// that difference's RMS over the training runs [sigmas]
};

/// Two effects fitted and scored together on the training runs (leave-one-run-out, as a single
/// candidate with both columns).
struct PairFit {
  EffectFit first, second;  /// the members: their single fits with the joint parameters
  double score = 0;         /// joint held-out gain - penalty for both members' parameters
  double heldout_gain = 0;
  std::vector<double> fold_gains;  /// joint held-out gain per training run
  /// What each member adds to the other alone: score - the other's single score.
  double adds_first = 0, adds_second = 0;
  /// Both physical with the joint parameters, and each adds more than the noise threshold and its
  /// model-form floor to the other.
  bool admissible = false;
};

struct Selection {
  std::vector<EffectFit> claimed;    /// claimed effects, most important first
  std::vector<EffectFit> ranking;    /// best per (kind, place) of the first round, ranking_size
  std::vector<Ambiguity> ambiguous;  /// the round at which the choice stopped undecided, if any
  /// Claims whose size, refitted about the updated model, is unphysical: not claimed.
  std::vector<EffectFit> refit_rejected;
  /// The best pairs of the first round's best candidates scored jointly, best first; `by_pair`
  /// when the claims are the best admissible pair rather than the greedy choice.
  std::vector<PairFit> pairs;
  bool by_pair = false;
  /// Claims that backfitting replaced (chosen again with the other claims' fits removed): the
  /// one-after-the-other claim and what replaced it (empty: dropped, nothing of its kind beating
  /// noise and floor beside the others), in the order it happened.
  std::vector<std::pair<std::string, std::string>> backfit_replaced;
  double null_score = 0;   /// best score over fits to pure noise
  Eigen::VectorXd sigma;   /// per channel noise estimate [K | m]
  double residual_ss = 0;  /// training residual, whitened
};

/// `cat` with heat-input candidates added on finer grids around its best heat-input places (scored
/// on the training residual as select_effects scores them, with the in-sample fits of `others`,
/// claims of `cat` beside the heat input, removed first), marched like the catalogue's own: the
/// grid's spacing bounds how well a place can be found, and a finer grid everywhere costs too much.
Catalogue with_refined_heat_inputs(const MarchModel& model, const Catalogue& cat,
                                   const CalibrationOptions& options,
                                   const std::vector<EffectFit>& others = {});

/// Per channel white-noise level from second differences of the residuals (robust, pooled).
Eigen::VectorXd noise_sigma(const std::vector<RunModel>& runs, int sensors,
                            const CalibrationOptions& options);

/// Chooses effects: leave-one-run-out gains, penalty, noise threshold, model-form floor; greedy
/// over up to options.max_effects effects, then the best pairs of the first round's best
/// candidates scored jointly (docs/calibration.md, "Pairs"): the best admissible pair replaces
/// the greedy claims when it scores above them by more than the spread of the per-run gains (or,
/// against one greedy claim, by more than the noise threshold and floor). Needs at least two
/// runs.
/// A candidate's size found about the model it updates (refit_alone): its parameters and, per
/// training run, its secant response per unit parameter ((#samples #channels) x 1: the updated
/// model's channels minus the declared model's, over the size). Empty columns: no size found.
struct Resized {
  std::vector<double> parameters;
  std::vector<Eigen::MatrixXd> columns;
};
using Resizer = std::function<Resized(const EffectFit&)>;

/// With `resize`, the best `options.resize_pool` candidates that are not linear in their parameter
/// and whose linearised fit is unphysical are first sized about the model they update, and their
/// columns replaced by the secant responses at that size, so that they are scored, judged and
/// paired as what they do at their size, not as their first-order shadow (a film halved needs
/// h -> 0 to its linearisation); their fits keep the linearised parameters in `linearised`.
Selection select_effects(const Catalogue& cat, const CalibrationOptions& options,
                         const Resizer& resize = {});

/// Why `p` (fitted parameters of `c`; for a per-run air, `run_parameters` per run) is not
/// physical on `runs` (the speeds their duty cycles use), empty when it is. Sets `duty_correlation`
/// of a per-run air.
std::string unphysical_reason(const Candidate& c, const std::vector<double>& p,
                              const std::vector<std::vector<double>>& run_parameters,
                              const std::vector<RunModel>& runs, const CalibrationOptions& options,
                              double* duty_correlation = nullptr);

/// Least squares min |A x - y|^2 (normal matrix g = A^T A, b = A^T y) of an air change at `knots`
/// within options.air_range_K and options.air_rate_K_per_h (ADMM on the bounds).
Eigen::VectorXd bounded_air(const Eigen::MatrixXd& g, const Eigen::VectorXd& b,
                            const std::vector<double>& knots, const CalibrationOptions& options);

/// Fits a per-run candidate (the air temperature) to one run from its temperature channels,
/// within the air's bounds; a run with an ambient sensor gives its air from the sensor instead.
std::vector<double> fit_run_parameters(const Candidate& c, int run, const RunModel& model,
                                       const Readout& r, const Eigen::VectorXd& sigma,
                                       const CalibrationOptions& options);

/// Whitened residual rows of one run: vec(#samples x #channels) of (measured - base) / sigma,
/// finite readings only.
struct Whitened {
  Eigen::VectorXd y;               /// kept rows
  std::vector<Eigen::Index> rows;  /// indices into the column-major vec
  std::vector<int> channel;        /// channel of each kept row
};
Whitened whitened(const RunModel& run, const Eigen::VectorXd& sigma);
/// The rows of `a` ((#samples #channels) x k, column-major channels) that `w` keeps, whitened.
Eigen::MatrixXd whitened_rows(const Eigen::MatrixXd& a, const Whitened& w,
                              const Eigen::VectorXd& sigma);

/// One run's residual and shared columns with a per-run air's least squares eliminated: the air is
/// fitted on the run's temperature rows (as the choice fits it), so y -> y - A (At'At)^-1 At' y_t
/// and the columns likewise; shared parameters fitted to them are then fitted jointly with the
/// air, which follows them. A run with an ambient sensor has its air read: only subtracted.
struct AirEliminated {
  Eigen::MatrixXd m;               /// shared columns, the air eliminated (whitened rows)
  Eigen::VectorXd y;               /// residual, the air eliminated (whitened rows)
  Eigen::MatrixXd a;               /// the air's columns (whitened rows); empty without an air
  std::vector<Eigen::Index> keep;  /// the rows the air is fitted on
};
/// `y` and `shared` (whitened rows of run `ri` as `w` keeps them) with the air `air` eliminated;
/// unchanged when `air` is null.
AirEliminated air_eliminated(const Candidate* air, const RunModel& run, const Readout& r,
                             const Whitened& w, const Eigen::VectorXd& y,
                             const Eigen::MatrixXd& shared, size_t ri, const Eigen::VectorXd& sigma,
                             const CalibrationOptions& options);
/// The air beside shared parameters `x`: fitted within its bounds to what y - shared x leaves on
/// the run's temperature rows (or read from the run's ambient sensor). `y` holds no air.
Eigen::VectorXd air_at(const Candidate& air, const RunModel& run, const AirEliminated& e,
                       const Eigen::VectorXd& y, const Eigen::MatrixXd& shared,
                       const Eigen::VectorXd& x, const CalibrationOptions& options);

/// Least squares from the normal equations g x = b, ridged by `ridge` x g's mean diagonal.
Eigen::VectorXd solve_ridge(const Eigen::MatrixXd& g, const Eigen::VectorXd& b, double ridge);

/// Whether `c`'s channel response is not linear in its parameter (films, heat that grows with
/// temperature, conductivity and capacity): its size needs the refit about the updated model.
bool nonlinear_in_parameter(const Candidate& c);

/// First-order lag of x sampled at `times` (exact for x linear between samples), y(0) = x(0).
Eigen::VectorXd lagged(const Eigen::VectorXd& times, const Eigen::VectorXd& x, double tau);

}  // namespace tt::calibration
