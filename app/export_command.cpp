// thermotwin export: the fitted compensation in the controllers' own formats (issue 20, item 5),
// with what each controller's law leaves of the model along the axis travel.
//   thermotwin export --model FIT.json --out DIR [--format F]... [--states CSV]...
//                     [--table-points N] [--grid N]
// Writes into DIR (all or nothing): per format a folder (sinumerik/, twincat/, heidenhain/,
// linuxcnc/) with the controller's files, and export.json / export.md with the laws' errors.
// See docs/cnc-export.md.
// 1. The model: the TCP's and the feed axis's models of fit.json on one temperature basis
//    (io::read_cnc_model).
// 2. The temperature states the laws are judged on: every basis function alone at one unit, and
//    with --states the samples of CSVs (time_s, sensor ids; a "_degC" suffix is dropped), each
//    from its own first sample (fit writes its held-out groups' as held_out/*_temperatures.csv).
// 3. Per format: the law (io::controller_law), its error against the model on the grid of positions
//    and the states (fitting::law_error), and its files (io::cnc_files).
#include <cmath>
#include <fstream>

#include "app/commands.hpp"
#include "core/errors.hpp"
#include "fitting/cnc_export.hpp"
#include "io/atomic_dir.hpp"
#include "io/cnc_model_in.hpp"
#include "io/cnc_out.hpp"
#include "io/sample_stream.hpp"

namespace tt::app {
namespace {

constexpr const char* kDirections[3] = {"dx", "dy", "dz"};

/// Sensor samples of a CSV as basis states (#samples x #basis).
Eigen::MatrixXd states_of_csv(const fitting::CncModel& model, const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw core::IoError(path.string() + ": cannot read (expected a CSV of sensor samples)");
  std::string line;
  if (!std::getline(in, line))
    throw core::DataError(path.string() + ": empty; expected a header time_s,<sensor ids>");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  std::vector<std::string> columns = io::stream_columns(line, path.string());
  for (std::string& c : columns)
    if (c.size() > 5 && c.compare(c.size() - 5, 5, "_degC") == 0) c.resize(c.size() - 5);
  std::vector<double> times;
  std::vector<Eigen::VectorXd> rows;
  Eigen::VectorXd values(static_cast<Eigen::Index>(columns.size()));
  for (int number = 2; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    double time = 0.0;
    if (!io::parsed_sample(line, time, values))
      throw core::DataError(path.string() + ": line " + std::to_string(number) + " has not " +
                            std::to_string(columns.size() + 1) + " fields");
    times.push_back(time);
    rows.push_back(values);
  }
  if (rows.empty()) throw core::DataError(path.string() + ": no sample after the header");
  Eigen::MatrixXd v(static_cast<Eigen::Index>(rows.size()), values.size());
  for (std::size_t i = 0; i < rows.size(); ++i) v.row(static_cast<Eigen::Index>(i)) = rows[i];
  try {
    return fitting::basis_states(model, columns,
                                 Eigen::Map<const Eigen::VectorXd>(times.data(), v.rows()), v);
  } catch (const core::DataError& e) {
    throw core::DataError(path.string() + ": " + e.what());
  }
}

nlohmann::json error_json(const fitting::LawError& e) {
  nlohmann::json j{{"positions", e.positions}, {"states", e.states}};
  for (std::size_t d = 0; d < 3; ++d)
    j[kDirections[d]] = {{"max_um", e.max[d] * 1e6},
                         {"rms_um", e.rms[d] * 1e6},
                         {"model_max_um", e.model_max[d] * 1e6}};
  return j;
}

std::string error_rows(const std::string& format, const std::string& states,
                       const fitting::LawError& e) {
  std::string rows;
  char buf[200];
  for (std::size_t d = 0; d < 3; ++d) {
    if (e.model_max[d] == 0.0) continue;
    std::snprintf(buf, sizeof buf, "| %s | %s | %s | %.4g | %.4g | %.4g |\n", format.c_str(),
                  states.c_str(), kDirections[d], e.max[d] * 1e6, e.rms[d] * 1e6,
                  e.model_max[d] * 1e6);
    rows += buf;
  }
  return rows;
}

}  // namespace

int export_command(const ExportArgs& args) {
  std::vector<io::CncFormat> formats;
  for (const std::string& f : args.formats) formats.push_back(io::format_of(f));
  if (formats.empty())
    formats = {io::CncFormat::sinumerik, io::CncFormat::twincat, io::CncFormat::heidenhain,
               io::CncFormat::linuxcnc};
  std::vector<std::filesystem::path> inputs{args.model};
  inputs.insert(inputs.end(), args.states.begin(), args.states.end());
  io::OutputDir out(args.out, inputs);

  // 1. The model.
  const io::CncModelFile file = io::read_cnc_model(args.model);
  const fitting::CncModel& model = file.model;

  // 2. The states.
  const Eigen::MatrixXd unit = fitting::unit_states(model);
  Eigen::MatrixXd sampled(0, unit.cols());
  nlohmann::json state_files = nlohmann::json::array();
  for (const std::filesystem::path& path : args.states) {
    const Eigen::MatrixXd s = states_of_csv(model, path);
    sampled.conservativeResize(sampled.rows() + s.rows(), Eigen::NoChange);
    sampled.bottomRows(s.rows()) = s;
    state_files.push_back({{"file", path.string()}, {"samples", s.rows()}});
  }

  // 3. Per format: law, error, files.
  nlohmann::json report{
      {"model", args.model.string()},      {"basis", model.basis},
      {"targets", file.targets},           {"ignored_targets", file.ignored_targets},
      {"feed_axis", model.feed_axis},      {"travel_m", {model.travel_min, model.travel_max}},
      {"table_points", args.table_points}, {"formats", nlohmann::json::object()}};
  if (!args.states.empty()) report["states"] = state_files;
  std::string md =
      "# CNC export: what each controller's law leaves of the model\n\n"
      "Compensation value = minus the model's predicted error. |law - model| over " +
      std::to_string(args.grid) +
      " positions along the travel; states: `per unit` is the constant alone and each basis "
      "function alone at one unit (1 K): the error per unit; `samples` are the " +
      std::to_string(sampled.rows()) + " samples of the --states files" +
      (args.states.empty() ? std::string(" (none given)") : std::string()) +
      ".\n\n| format | states | direction | max [um] | RMS [um] | model max [um] |\n"
      "|---|---|---|---|---|---|\n";
  for (io::CncFormat format : formats) {
    const std::string name = io::format_name(format);
    const fitting::ControllerLaw law = io::controller_law(format, model, args.table_points);
    nlohmann::json entry;
    const fitting::LawError per_unit = fitting::law_error(model, law, unit, args.grid);
    entry["error_per_unit"] = error_json(per_unit);
    md += error_rows(name, "per unit", per_unit);
    if (sampled.rows() > 0) {
      const fitting::LawError on_samples = fitting::law_error(model, law, sampled, args.grid);
      entry["error_on_states"] = error_json(on_samples);
      md += error_rows(name, "samples", on_samples);
    }
    std::filesystem::create_directories(out.path() / name);
    for (const io::CncFile& f : io::cnc_files(format, model, law, args.model.string())) {
      io::write_file_atomically(out.path() / name / f.name, f.text);
      entry["files"].push_back(name + "/" + f.name);
    }
    report["formats"][name] = entry;
  }
  io::write_file_atomically(out.path() / "export.json", report.dump(2) + "\n");
  io::write_file_atomically(out.path() / "export.md", md);
  out.commit();
  return 0;
}

}  // namespace tt::app
