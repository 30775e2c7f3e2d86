// Writers of the fitting results: fit.json (every candidate and the chosen model per target),
// the modelling result record of DB3401/T 326-2024 section 8 (JSON and Markdown), and a CSV of
// the compensation each model would apply. SI inside; µm, mm, °C and rpm only in these files,
// with the unit in the field or column name.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fitting/group.hpp"
#include "fitting/models.hpp"
#include "fitting/selection.hpp"

namespace tt::io {

/// Cutting data, recorded when the errors were measured while cutting (section 8.2.2).
struct CuttingConditions {
  std::string tool;
  std::string workpiece_material;
  /// free text, e.g. "160 x 160 x 50 mm"
  std::string workpiece_size;
  /// [m/s]
  double cutting_speed = 0.0;
  /// [m per revolution]
  double feed = 0.0;
  /// [m]
  double depth_of_cut = 0.0;
};

/// What the standard's section 8.2.1 asks the modelling record to state.
struct ModellingConditions {
  std::string machine_model;
  std::string machine_number;
  /// X, Y, Z travels [m]
  double travel_x = 0.0;
  double travel_y = 0.0;
  double travel_z = 0.0;
  /// ISO 8601, e.g. "2026-11-21"
  std::string modelling_date;
  /// [K]
  double initial_ambient_temperature = 0.0;
  /// [rad/s]
  double max_spindle_speed = 0.0;
  /// [m/s]
  double max_feed_rate = 0.0;
  std::optional<CuttingConditions> cutting;
};

/// Today's date in UTC, ISO 8601 ("2026-11-26"): the modelling date of a record written now. With
/// SOURCE_DATE_EPOCH set (seconds since 1970, the reproducible-builds convention) that instant's
/// date, so that a rerun writes the same record.
std::string modelling_date_today();

/// A fitted model's coefficients: intercept and named terms [µm, µm/K] for linear models, the
/// ridge functions for PPR; with the sensors and the operating inputs (e.g. "speed_rpm") it reads,
/// so that io/fit_model_in.hpp can evaluate it again.
nlohmann::json model_json(const fitting::FittedModel& model);

/// fit.json: per target the groups' roles, every (method, m, model) candidate with its
/// coefficients and validation S, S_M, S_σ, and the chosen model with its test S, S_M, S_σ;
/// sensor count tables when given.
nlohmann::json fit_json(const std::vector<fitting::Evaluation>& evaluations,
                        const std::vector<fitting::SensorCountTable>& sensor_counts = {});

void write_fit_json(const std::filesystem::path& path,
                    const std::vector<fitting::Evaluation>& evaluations,
                    const std::vector<fitting::SensorCountTable>& sensor_counts = {});

/// The section 8 modelling record for the chosen model of each target.
nlohmann::json modelling_record_json(const ModellingConditions& conditions,
                                     const std::vector<fitting::Evaluation>& evaluations);

std::string modelling_record_markdown(const ModellingConditions& conditions,
                                      const std::vector<fitting::Evaluation>& evaluations);

/// Writes both forms of the record, each through a temporary file and a rename.
void write_modelling_record(const std::filesystem::path& json_path,
                            const std::filesystem::path& markdown_path,
                            const ModellingConditions& conditions,
                            const std::vector<fitting::Evaluation>& evaluations);

/// CSV, one row per (group, sample, model): group, time_s, target, measured_um, predicted_um,
/// compensation_um (= −predicted, the shift of the work origin) and
/// residual_after_compensation_um (= measured + compensation).
std::string compensation_csv(const std::vector<fitting::FittedModel>& models,
                             const std::vector<fitting::Group>& groups);

void write_compensation_csv(const std::filesystem::path& path,
                            const std::vector<fitting::FittedModel>& models,
                            const std::vector<fitting::Group>& groups);

}  // namespace tt::io
