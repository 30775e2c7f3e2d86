#include "io/export_out.hpp"

#include <cstdio>
#include <string>

#include "core/directions.hpp"
#include "core/units.hpp"
#include "io/atomic_dir.hpp"
#include "io/cnc_out.hpp"

namespace tt::io {
namespace {

nlohmann::json error_json(const fitting::LawError& e) {
  nlohmann::json j{{"positions", e.positions}, {"states", e.states}};
  for (std::size_t d = 0; d < 3; ++d)
    j[core::kDirectionNames[d]] = {{"max_um", e.max[d] * core::kMicrometresPerMetre},
                                   {"rms_um", e.rms[d] * core::kMicrometresPerMetre},
                                   {"model_max_um", e.model_max[d] * core::kMicrometresPerMetre}};
  return j;
}

/// export.md's table rows of one law on one set of states.
std::string error_rows(const std::string& format, const std::string& states,
                       const fitting::LawError& e) {
  std::string rows;
  char buf[200];
  for (std::size_t d = 0; d < 3; ++d) {
    if (e.model_max[d] == 0.0) continue;
    std::snprintf(buf, sizeof buf, "| %s | %s | %s | %.4g | %.4g | %.4g |\n", format.c_str(),
                  states.c_str(), core::kDirectionNames[d], e.max[d] * core::kMicrometresPerMetre,
                  e.rms[d] * core::kMicrometresPerMetre,
                  e.model_max[d] * core::kMicrometresPerMetre);
    rows += buf;
  }
  return rows;
}

std::string markdown_head(const ExportSource& source) {
  return "# CNC export: what each controller's law leaves of the model\n\n"
         "Compensation value = minus the model's predicted error. |law - model| over " +
         std::to_string(source.grid) +
         " positions along the travel; states: `per unit` is the constant alone and each basis "
         "function alone at one unit (1 K): the error per unit; `samples` are the " +
         std::to_string(source.samples->states.rows()) + " samples of the --states files" +
         (source.state_files.empty() ? std::string(" (none given)") : std::string()) +
         ".\n\n| format | states | direction | max [um] | RMS [um] | model max [um] |\n"
         "|---|---|---|---|---|---|\n";
}

nlohmann::json export_json_head(const ExportSource& source) {
  const fitting::CncModel& model = source.file->model;
  nlohmann::json report{
      {"model", source.model.string()},      {"basis", model.basis},
      {"targets", source.file->targets},     {"ignored_targets", source.file->ignored_targets},
      {"feed_axis", model.feed_axis},        {"travel_m", {model.travel_min, model.travel_max}},
      {"table_points", source.table_points}, {"formats", nlohmann::json::object()}};
  if (source.state_files.empty()) return report;
  report["states"] = nlohmann::json::array();
  for (std::size_t f = 0; f < source.state_files.size(); ++f)
    report["states"].push_back(
        {{"file", source.state_files[f].string()}, {"samples", source.samples->per_file[f]}});
  return report;
}

}  // namespace

void write_export(const std::filesystem::path& dir, const studies::CncExportReport& report,
                  const ExportSource& source) {
  nlohmann::json doc = export_json_head(source);
  std::string md = markdown_head(source);
  for (const studies::FormatLaw& law : report.laws) {
    const std::string name = format_name(law.format);
    nlohmann::json entry;
    entry["error_per_unit"] = error_json(law.per_unit);
    md += error_rows(name, "per unit", law.per_unit);
    if (law.on_samples) {
      entry["error_on_states"] = error_json(*law.on_samples);
      md += error_rows(name, "samples", *law.on_samples);
    }
    std::filesystem::create_directories(dir / name);
    for (const CncFile& f :
         cnc_files(law.format, source.file->model, law.law, source.model.string())) {
      write_file_atomically(dir / name / f.name, f.text);
      entry["files"].push_back(name + "/" + f.name);
    }
    doc["formats"][name] = entry;
  }
  write_file_atomically(dir / "export.json", doc.dump(2) + "\n");
  write_file_atomically(dir / "export.md", md);
}

}  // namespace tt::io
