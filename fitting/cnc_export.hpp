// The compensation as a CNC takes it (issue 20, item 5). A fitted model gives, per direction, the
// drift of the TCP (position independent) and the feed axis's error polynomial in the axis
// position, both linear in the same temperature basis (the models' regressors). A controller
// cannot evaluate that as it stands: SINUMERIK takes a straight line per axis, TwinCAT and a
// Heidenhain PLC interpolate tables of (position, value), LinuxCNC's HAL evaluates what its
// components can build, each with its own rounding. Each such law is built here from the model,
// still linear in the basis (so the PLC sums it), and compared with the model along the travel.
// Values are SI (m); the compensation value is the negative of the predicted error, the value a
// controller adds to the axis position.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <variant>
#include <vector>

#include "core/enum_names.hpp"
#include "fitting/features.hpp"
#include "fitting/models.hpp"

namespace tt::fitting {

/// Linear models over one shared basis: the constant 1, then the regressors of `features`
/// (feature_names order).
struct LinearBasis {
  /// the union of the models' sensors, inputs and time constants
  FeatureMap features;
  /// 1 + #features names: "1", then feature_names(features)
  std::vector<std::string> names;
  /// #models x (1 + #features): model m's error = coefficients.row(m) · [1; φ] [m per unit]
  Eigen::MatrixXd coefficients;
};

/// The models on one basis. Models must be linear (least_squares, ridge, distributed_lag or
/// no_compensation) with named features; throws DataError naming the first model that is not
/// (projection_pursuit, cnn_bigru_attention) or whose coefficients do not match its features.
LinearBasis linear_basis(const std::vector<FittedModel>& models);

/// What the controllers approximate. Direction d = 0, 1, 2 is x, y, z.
struct CncModel {
  std::vector<std::string> basis;  /// "1", then the regressors' names (LinearBasis::names)
  FeatureMap features;             /// gives the regressors from sensor samples (FeatureStream)
  std::string feed_axis;           /// name of the feed axis, e.g. "X"; empty: none
  int feed_direction = 0;          /// the direction the feed axis moves along
  double travel_min = 0.0, travel_max = 0.0;  /// the axis travel [m]; equal: no position term
  /// per direction: #basis coefficients of the TCP's predicted error [m per unit]; zero where the
  /// model has no TCP target in that direction
  std::array<Eigen::VectorXd, 3> tcp;
  /// per direction: (degree + 1) x #basis coefficients c_k of the axis points' predicted error
  /// e(p) = Σ_k c_k p^k, p the axis position [m]; 0 rows: no feed axis
  std::array<Eigen::MatrixXd, 3> axis;
};

/// The model's compensation value (−predicted error) in direction d at axis position p [m] for a
/// basis state b (#basis values, b(0) = 1) [m].
double model_compensation(const CncModel& model, int d, double p, const Eigen::VectorXd& b);

/// SINUMERIK's temperature compensation: ΔK = K_abs + (p − p_0)·tan β per axis, with K_abs and
/// tan β linear in the basis. tan β acts along the feed axis's own position only, so it is zero
/// for the other directions, whose K_abs is the best constant over the travel.
struct LineLaw {
  double reference = 0.0;  /// p_0 [m]: the middle of the travel
  /// per direction: #basis coefficients of K_abs [m per unit] and of tan β [per unit]
  std::array<Eigen::VectorXd, 3> value, slope;
};

/// A table of compensation values at equidistant positions along the feed axis, linearly
/// interpolated between them and held constant beyond the ends; the PLC forms each entry as the
/// sum over the basis. `quantum` > 0 rounds the summed value to the controller's unit (to the
/// nearest, or toward zero with `truncate`).
struct TableLaw {
  Eigen::VectorXd positions;              /// #points ascending [m]
  std::array<Eigen::MatrixXd, 3> values;  /// per direction: #points x #basis [m per unit]
  double quantum = 0.0;                   /// [m]; 0: none
  bool truncate = false;
};

/// The model's polynomial itself, evaluated by the controller (TCP term in c_0), with the same
/// rounding options as TableLaw.
struct PolynomialLaw {
  std::array<Eigen::MatrixXd, 3> coefficients;  /// per direction: (degree + 1) x #basis
  double quantum = 0.0;
  bool truncate = false;
};

using ControllerLaw = std::variant<LineLaw, TableLaw, PolynomialLaw>;

/// The least-squares straight line of the model's compensation over the travel (continuous, exact),
/// per basis function; p_0 the middle of the travel.
LineLaw line_law(const CncModel& model);

/// The model's compensation tabled at `points` >= 2 equidistant positions over the travel (one
/// position when the model has no travel). Throws DataError on points < 2 or quantum < 0.
TableLaw table_law(const CncModel& model, int points, double quantum, bool truncate);

/// The model's compensation as its polynomial (TCP term added to c_0).
PolynomialLaw polynomial_law(const CncModel& model, double quantum, bool truncate);

/// The law's compensation value in direction d at position p for basis state b [m].
double law_compensation(const ControllerLaw& law, int d, double p, const Eigen::VectorXd& b);

/// What a law leaves of the model along the travel, per direction.
struct LawError {
  std::array<double, 3> max{}, rms{};  /// |law − model| over positions and states [m]
  std::array<double, 3> model_max{};   /// largest |model compensation| on the same grid [m]
  int positions = 0, states = 0;
};

/// law − model on `grid` >= 2 equidistant positions over the travel (one when it has none) and
/// each row of `states` (#states x #basis basis values; column 0 is 1 for a machine's state, and
/// any value for a basis function's share, e.g. unit_states). Throws DataError on
/// a states matrix whose columns do not match the basis.
LawError law_error(const CncModel& model, const ControllerLaw& law, const Eigen::MatrixXd& states,
                   int grid);

/// #basis x #basis identity: the constant alone, then each basis function alone at one unit
/// (1 K, 1 rpm); law_error over it gives the law's error per unit of each basis function.
Eigen::MatrixXd unit_states(const CncModel& model);

/// The basis states of sensor samples: #samples x #basis, [1, regressors] as FeatureStream forms
/// them from the first sample on (the first sample is the reference of the increments).
/// `columns` name the values of each sample; `times` [s] ascending, `values` #samples x
/// #columns. Throws DataError naming a sensor or input the basis reads that `columns` lacks.
Eigen::MatrixXd basis_states(const CncModel& model, const std::vector<std::string>& columns,
                             const Eigen::VectorXd& times, const Eigen::MatrixXd& values);

/// The four controllers.
enum class CncFormat { sinumerik, twincat, heidenhain, linuxcnc };

/// The formats' names on the command line and in export.json.
inline constexpr std::array<core::Named<CncFormat>, 4> kCncFormatNames{{
    {CncFormat::sinumerik, "sinumerik"},
    {CncFormat::twincat, "twincat"},
    {CncFormat::heidenhain, "heidenhain"},
    {CncFormat::linuxcnc, "linuxcnc"},
}};
static_assert(core::one_to_one(kCncFormatNames));

/// axis.L.eoffset-scale of LinuxCNC's HAL file: the external offset's count [mm].
inline constexpr double kLinuxcncScaleMm = 1e-5;

/// How each controller's law is built from the model (one place: the files and the error figures
/// use the same law).
/// sinumerik: line_law; twincat: table_law at `table_points`, no rounding (LREAL);
/// heidenhain: table_law at `table_points`, rounded to 0.1 µm (PLC module 9231's unit);
/// linuxcnc: polynomial_law, truncated to the eoffset count (kLinuxcncScaleMm).
ControllerLaw controller_law(CncFormat format, const CncModel& model, int table_points);

}  // namespace tt::fitting
