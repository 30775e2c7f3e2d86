// The CLI's commands. Each is a thin driver: numbered steps that follow the data flow, from
// reading inputs to writing one output directory atomically.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/plot.hpp"

namespace tt::app {

struct MeshArgs {
  std::filesystem::path case_file, out;
};
struct RunArgs {
  std::filesystem::path case_file, out;
  bool quiet = false;
  bool resume = false;              /// continue from OUT.checkpoint when there is one
  double checkpoint_every_s = 600;  /// wall time between checkpoints; < 0: none
  int stop_after_steps = 0;         /// tests: save a checkpoint after this many steps and exit 3
  std::filesystem::path dump;       /// tests: temperatures and displacements as raw doubles
  std::filesystem::path rom;  /// a reduced model (reduce --out DIR): thermal transient from it
  bool verify = false;        /// with rom: recompute the output times in full and compare
  std::filesystem::path duty_cycle;  /// another duty cycle: CSV "time_s,speed_rpm"
  std::optional<double> end_s;       /// with duty_cycle: the run's end [s] (default: the case's)
};

struct ProbesArgs {
  std::filesystem::path in, from_run, out, truth;
  std::optional<double> speed_rpm, sample_rate_hz, probe_distance_mm;
};

struct PlaceArgs {
  std::filesystem::path case_file, from_run, out;
  std::filesystem::path rom;  /// a reduced model (reduce --out DIR) to simulate the case on
  bool full = false;          /// simulate in full order (default: a reduced model built on the fly)
  int samples = 100, bins = 20, m_max = 6;
  bool sensor_noise = false;  /// place on readings with the campaign's sensor noise
  bool quiet = false;
  std::vector<std::string> methods;  /// placement methods by name; empty: all but observer_variance
  /// also place for detection of the calibration catalogue's effects (placement.json
  /// catalogue_detection)
  bool catalogue_detection = false;
  /// with catalogue_detection: the sizes each kind is asked to be seen at (unset: the defaults of
  /// studies::CatalogueSizes)
  std::optional<double> detect_heat_w, detect_film_share, detect_source_per_k,
      detect_material_change, detect_air_k;
};

struct FitArgs {
  std::filesystem::path case_file, out;
  std::filesystem::path rom;  /// a reduced model (reduce --out DIR) to run the campaign on
  bool full = false;          /// the campaign in full order (default: a reduced model on the fly)
  double hours = 5, required_sm_um = 1.0;
  bool quick = false, quiet = false;
  bool network = false;  /// also try the CNN-BiGRU-attention network (seed 004)
  /// also place for estimation (observer_variance) on the campaign's reduced model
  bool estimation = false;
};

/// fit --data RUN...: measured runs with no machine model (app/fit_data_command.cpp).
struct FitDataArgs {
  std::vector<std::filesystem::path> runs;
  /// held-out runs, tested whole (then no test window is cut from `runs`)
  std::vector<std::filesystem::path> test_runs;
  std::filesystem::path out;
  std::optional<double> test_from_s, test_to_s;  /// test window; default: the published one, if any
  bool quick = false, quiet = false;
  bool network = false;  /// also try the CNN-BiGRU-attention network (seed 004)
};

/// calibrate: with --case the model-based path, without it the data-driven one.
struct CalibrateArgs {
  std::filesystem::path case_file, out;
  std::vector<std::filesystem::path> train, test;
  std::optional<double> split_s;  /// a run given as --train and --test: train before, test from
  bool full = false;              /// with --case: march the full model, not the reduced one
  bool no_refit = false;          /// with --case: keep the claims' linearised sizes
  bool quiet = false;
};

/// reduce CASE --out DIR: the reduced-order twin and its validation (app/reduce_command.cpp).
struct ReduceArgs {
  std::filesystem::path case_file, out;
  bool quick_validation = false;  /// validate on the case's own duty cycle only
  bool quiet = false;
};

/// The physics observer's sensors, noise and consistency test (observe, compensate --rom;
/// docs/observer.md); app/observer_options.cpp turns them into a solvers::ObserverSetup.
struct ObserverOptions {
  std::vector<std::string> sensors;  /// empty: every sensor of the run the model names
  /// white noise per reading [K]: one value for every sensor, or one per sensor in their order
  std::vector<double> sensor_sigma_k{0.05};
  double heat_walk_w = 4.0;             /// random walk of each unknown heat input [W/sqrt(h)]
  double heat_initial_w = 2.0;          /// each unknown heat input's spread at t = 0 [W]
  double air_walk_k = 0.5;              /// random walk of the air offset [K/sqrt(h)]
  double air_initial_k = 0.3;           /// the air offset's spread at t = 0 [K]
  double state_walk_k = 0;              /// white noise on every reduced state [K/sqrt(h)]
  double sensor_offset_k = 0.5;         /// per-sensor offset state: spread at t = 0 [K]
  double sensor_offset_walk_k = 0.05;   /// per-sensor offset state: random walk [K/sqrt(h)]
  bool widen_on_inconsistency = false;  /// widen sigma by sqrt(window NIS / readings) when > 1
  /// the correction's and expansion's terms only once the filter says recalibrate, or weighted
  /// by the readings' departure from the declared model before it (at most one of the two)
  bool changed_terms_after_alarm = false, changed_terms_on_evidence = false;
  double drift_relative_sigma = 0.04;    /// the drift rows' own error, relative to the drift [-]
  double correction_relative_sigma = 0;  /// the corrections' error, relative to them [-]
  /// each material's expansion error, relative [-]: one value for all or one per material
  std::vector<double> expansion_relative_sigma{0};
  /// factor on the reported drift sigma: one value for every target or one per target; empty: 1
  std::vector<double> drift_sigma_scale;
  /// with drift readings: the factor on the sigma of the filter that reads them (calibrated with
  /// the probe cycle); empty: drift_sigma_scale
  std::vector<double> probed_drift_sigma_scale;
  /// a sigma_calibration.json (observe --train): its factors in place of the two above
  std::filesystem::path sigma_calibration;
  double window_s = 1800, sustain_s = 900, probability = 0.999;  /// consistency test
  double sensor_fault_sigmas = 4;  /// a sensor's offset beyond this many sigmas: faulty (0: off)
  /// a reading held this many sigmas from the declared model's run: recalibrate (0: off)
  double model_residual_sigmas = 3;
  /// time constant of the residuals' mean that --changed-terms-on-evidence weighs [s] (0: none)
  double evidence_time_s = 300;
  /// the residuals' mean (in sigmas) at which that weight starts to rise from 0 (1 at
  /// model_residual_sigmas)
  double evidence_onset_sigmas = 1;
  /// whether --evidence-time-s or --evidence-onset-sigmas was given: if not, --sigma-calibration
  /// takes its file's
  bool evidence_given = false;
  /// > 0: the run's (the stream's) displacement columns named after targets are read as drift
  /// readings, one every this many seconds (a probe cycle); 0: temperatures only
  double drift_readings_every_s = 0;
  double drift_reading_sigma_um = 0.3;  /// white noise of a drift reading [um]
};

/// compensate --model FIT.json | --rom DIR: live compensation (app/compensate_command.cpp).
struct CompensateArgs {
  std::filesystem::path model;
  std::filesystem::path rom;        /// a reduced model: the physics observer instead of a fit
  std::filesystem::path case_file;  /// with rom: the case it was built from (default: its record)
  ObserverOptions observer;         /// with rom
  std::optional<double> initial_temperature_c;  /// with rom: the machine's at t = 0 (the case's)
  /// with rom: a recorded run's meta.json: its sensors are read at their positions (as `observe`
  /// reads them), its initial temperature is the machine's at t = 0 unless given
  std::filesystem::path meta;
  /// with rom: the observer's period [s]: the samples of a period are assimilated as one reading
  /// (their mean), so a fast stream costs one covariance step per period; 0: every sample
  double filter_every_s = 1.0;
  /// with model: a network is evaluated at a sample at least this long after its last
  /// evaluation [s], its prediction held between; 0: every sample
  double network_every_s = 1.0;
  /// with rom: the first sample is the model's t = 0 (a cold start there), whatever its time_s
  bool from_first_sample = false;
  std::filesystem::path in;   /// a CSV file, followed as it grows; empty: standard input
  std::filesystem::path out;  /// empty: standard output
  bool until_eof = false;     /// with in: stop at its end instead of following it
  double idle_s = 0.0;        /// with in: stop when it has not grown for this long [s]; 0: never
  int poll_ms = 5;            /// with in: how often to look for new lines at its end [ms]
  bool flush = false;         /// flush after every line (always on a terminal)
  /// output held for a reader that falls behind before lines are dropped [MiB]
  double max_behind_mib = 16.0;
  /// MODEL=STREAM: the stream's column STREAM read as the model's MODEL (a sensor or an input)
  std::vector<std::string> columns;
};

/// observe CASE --rom DIR --data RUN --out DIR: the physics observer on a measured run
/// (app/observe_command.cpp, docs/observer.md).
struct ObserveArgs {
  std::filesystem::path case_file, rom, out;
  std::filesystem::path data;  /// the run to observe; empty: calibrate only
  /// runs whose drift was measured: the sigma factors are calibrated on them
  /// (sigma_calibration.json) and, with data, used on it
  std::vector<std::filesystem::path> train;
  /// with train: runs of a machine that has changed, drift measured: the correction's and the
  /// expansion's relative sigma are chosen on them
  std::vector<std::filesystem::path> changed;
  double truth_sigma_um = 0;  /// white noise of the training runs' measured drift [um]
  double coverage = 0.95;     /// the share of training samples the ±2 sigma band is to hold
  /// with changed and the terms on evidence: the evidence setting chosen on the changed runs
  /// (studies::ChangedMachineSigma::evidence_chosen) instead of the options'
  bool choose_evidence = false;
  ObserverOptions observer;
  bool quiet = false;
};

/// export --model FIT.json --out DIR: the compensation in the controllers' formats
/// (app/export_command.cpp, docs/cnc-export.md).
struct ExportArgs {
  std::filesystem::path model, out;
  std::vector<std::string> formats;  /// sinumerik, twincat, heidenhain, linuxcnc; empty: all
  /// CSVs of sensor samples (time_s, ids), each from its own first sample: the states to judge on
  std::vector<std::filesystem::path> states;
  int table_points = 51;  /// TwinCAT and Heidenhain table entries over the travel
  int grid = 1001;        /// positions over the travel where the laws are judged
};

int export_command(const ExportArgs& args);
int mesh_command(const MeshArgs& args);
int observe_command(const ObserveArgs& args);
int compensate_command(const CompensateArgs& args);
int reduce_command(const ReduceArgs& args);
int fit_data_command(const FitDataArgs& args);
int calibrate_data_command(const CalibrateArgs& args);
/// calibrate --case CASE: the declared model's residual on measured runs traced to a missing
/// effect, the augmented case evaluated on the test runs (app/calibrate_case_command.cpp).
int calibrate_command_with_case(const CalibrateArgs& args);
int fit_command(const FitArgs& args);
int place_command(const PlaceArgs& args);
int probes_command(const ProbesArgs& args);
int run_command(const RunArgs& args);

/// The one plotting entry point (io/plot.hpp).
using io::plot;

/// Progress on stderr, at most every 10 % of the simulated time.
void report_progress(const std::string& stage, double done, double total);

}  // namespace tt::app
