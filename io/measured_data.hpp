// Measured runs in the exchange format of docs/measured-data.md (meta.json + data.csv): read with
// every rejection the format lists, and written (the generator of test data uses the writer).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace tt::io {

struct MeasuredSensor {
  std::string id;
  std::optional<Eigen::Vector3d> position;  /// [m], absent when null
};

struct MeasuredProbe {
  std::string id;
  std::optional<Eigen::Vector3d> point;      /// [m]
  std::optional<Eigen::Vector3d> direction;  /// unit vector
};

/// A figure published for the data set (meta.json `published`): the model that reached it and
/// where it is published, the held-out window, the MAE per displacement channel, other models'.
struct PublishedFigure {
  std::string model, source, note;
  double from_s = 0, to_s = 0;                                         /// held-out window [s]
  std::map<std::string, double> mae_um;                                /// per displacement id [um]
  std::map<std::string, std::map<std::string, double>> others_mae_um;  /// model -> id -> [um]
};

struct MeasuredRun {
  std::filesystem::path folder;
  std::string machine;  /// "SB-1" means docs/SB-1-spindle-box.md
  std::string run;
  std::vector<MeasuredSensor> sensors;
  std::vector<MeasuredProbe> displacements;
  std::vector<std::string> inputs;                                 /// e.g. "speed_rpm"
  std::optional<std::string> ambient_sensor;                       /// id of one of `sensors`
  std::optional<double> initial_temperature_c, nominal_ambient_c;  /// [degC]
  /// meta.json's machine_box_m: every sensor and probe position lies inside [m].
  std::optional<Eigen::AlignedBox3d> machine_box;
  std::optional<PublishedFigure> published;  /// meta.json's published
  Eigen::VectorXd time;                      /// #samples [s], strictly increasing
  Eigen::MatrixXd input_values;              /// #samples x #inputs (speeds in rpm)
  Eigen::MatrixXd temperature;   /// #samples x #sensors [K]; NaN where the reading is missing
  Eigen::MatrixXd displacement;  /// #samples x #probes [m]; NaN where the reading is missing
  nlohmann::json meta;           /// the whole meta.json, keys not interpreted carried along
};

struct MeasuredReadLimits {
  /// Positions must lie inside (a known machine); meta.json's machine_box_m when not given.
  std::optional<Eigen::AlignedBox3d> machine_box;
  std::size_t max_bytes = std::size_t(2) << 30;  /// data.csv larger than this is rejected
  std::size_t max_rows = 50'000'000;             /// more rows than this are rejected
};

/// Reads folder/meta.json and folder/data.csv. Throws DataError naming the file, the line and the
/// column (or the JSON key) for: a missing, duplicated or unknown column, a time that does not
/// increase, text or a non-finite number in a number cell, a position outside the machine's box,
/// an unknown unit or format, meta.json or data.csv that is a folder; IoError when a file cannot be
/// read. Empty cells stay NaN.
MeasuredRun read_measured_run(const std::filesystem::path& folder,
                              const MeasuredReadLimits& limits = {});

/// Reads a run's meta.json alone (its sensors and their positions, probes, inputs, initial and
/// ambient temperatures; no samples): for a stream whose samples come elsewhere. Throws as
/// read_measured_run does for meta.json.
MeasuredRun read_measured_meta(const std::filesystem::path& meta_json,
                               const MeasuredReadLimits& limits = {});

/// True when `a` and `b` name one run folder (relative paths and symbolic links resolved).
bool same_run(const std::filesystem::path& a, const std::filesystem::path& b);

/// Throws DataError naming the run when one folder appears twice in `folders`, given on the
/// command line as `option` ("--data", "--train", ...).
void require_distinct_runs(const std::vector<std::filesystem::path>& folders,
                           const std::string& option);

/// Throws DataError naming the run when a folder of `a` (given as `a_option`) is also in `b`
/// (given as `b_option`); `why` says how to proceed.
void require_disjoint_runs(const std::vector<std::filesystem::path>& a,
                           const std::vector<std::filesystem::path>& b, const std::string& a_option,
                           const std::string& b_option, const std::string& why);

/// Writes a run in the same format (folder created; files via temporary names).
void write_measured_run(const std::filesystem::path& folder, const MeasuredRun& run);

}  // namespace tt::io
