// thermotwin export: the fitted compensation in the controllers' own formats (issue 20, item 5),
// with what each controller's law leaves of the model along the axis travel.
//   thermotwin export --model FIT.json --out DIR [--format F]... [--states CSV]...
//                     [--table-points N] [--grid N]
// Writes into DIR (all or nothing): per format a folder (sinumerik/, twincat/, heidenhain/,
// linuxcnc/) with the controller's files, and export.json / export.md with the laws' errors.
// See docs/cnc-export.md.
// 1. The model: the TCP's and the feed axis's models of fit.json on one temperature basis
//    (io::read_cnc_model); with --states the samples of CSVs (time_s, sensor ids; a "_degC" suffix
//    is dropped) as basis states, each from its own first sample (fit writes its held-out groups'
//    as held_out/*_temperatures.csv; io::read_state_samples).
// 2. The study (studies/cnc_export.hpp): per format the law (fitting::controller_law) and its
//    error against the model on the grid of positions, per unit of each basis function and on
//    the sampled states.
// 3. The files (io/export_out.hpp): the controllers' files, export.json and export.md.
#include <vector>

#include "app/commands.hpp"
#include "io/atomic_dir.hpp"
#include "io/cnc_model_in.hpp"
#include "io/cnc_out.hpp"
#include "io/export_out.hpp"
#include "studies/cnc_export.hpp"

namespace tt::app {

int export_command(const ExportArgs& args) {
  std::vector<fitting::CncFormat> formats;
  for (const std::string& f : args.formats) formats.push_back(io::format_of(f));
  if (formats.empty())
    for (const auto& named : fitting::kCncFormatNames) formats.push_back(named.value);
  std::vector<std::filesystem::path> inputs{args.model};
  inputs.insert(inputs.end(), args.states.begin(), args.states.end());
  io::OutputDir out(args.out, inputs);
  // 1. The model and the sampled states.
  const io::CncModelFile file = io::read_cnc_model(args.model);
  const io::StateSamples samples = io::read_state_samples(file.model, args.states);
  // 2. Per format: law and error.
  const studies::CncExportReport report =
      studies::cnc_export({&file.model, formats, samples.states, args.table_points, args.grid});
  // 3. The files.
  io::write_export(out.path(), report,
                   {args.model, &file, args.states, &samples, args.table_points, args.grid});
  out.commit();
  return 0;
}

}  // namespace tt::app
