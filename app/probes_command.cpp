// thermotwin probes: spindle drift from four non-contact probes (patent CN101628396).
//   thermotwin probes --in RAW.csv --out DIR            recover drift and tilt from raw readings
//   thermotwin probes --from-run RUNDIR --out DIR       the same on a virtual signal made from a
//                                                       finished run's probe points
#include <iostream>

#include "app/commands.hpp"
#include "core/errors.hpp"
#include "io/atomic_dir.hpp"
#include "io/csv_out.hpp"
#include "probes/command.hpp"

namespace tt::app {

int probes_command(const ProbesArgs& args) {
  probes::ProbeOptions options;
  options.constants.speed_rpm = args.speed_rpm;
  options.constants.sample_rate_hz = args.sample_rate_hz;
  options.constants.probe_distance_mm = args.probe_distance_mm;
  if (!args.truth.empty()) options.truth_csv = args.truth;
  // The output is claimed first: one that is refused fails before any work.
  io::OutputDir out(args.out, {args.in, args.from_run, args.truth});
  std::filesystem::path raw = args.in;

  if (!args.from_run.empty()) {
    // 1. The drift history at the run's two axial probe points (thermal_error.csv, um -> m).
    const io::CsvTable te = io::read_numeric_csv(args.from_run / "thermal_error.csv");
    probes::DriftHistory history;
    for (Eigen::Index r = 0; r < te.rows.rows(); ++r) {
      probes::DriftSample s;
      s.time_s = te.rows(r, te.column_index("time_s"));
      s.drift.x1_m = 1e-6 * te.rows(r, te.column_index("dx_z1_um"));
      s.drift.y1_m = 1e-6 * te.rows(r, te.column_index("dy_z1_um"));
      s.drift.x2_m = 1e-6 * te.rows(r, te.column_index("dx_z2_um"));
      s.drift.y2_m = 1e-6 * te.rows(r, te.column_index("dy_z2_um"));
      s.drift.z_m = 1e-6 * te.rows(r, te.column_index("dz_um"));
      history.push_back(s);
    }
    // 2. A virtual spindle with 5 um runout and 0.1 um noise read at those times.
    probes::VirtualProbeSetup setup;
    setup.speed_rpm = args.speed_rpm.value_or(3000.0);
    setup.sample_rate_hz = args.sample_rate_hz.value_or(10000.0);
    setup.probe_distance_m = 1e-3 * args.probe_distance_mm.value_or(70.0);
    setup.runout_plane1 = probes::spindle_runout(5e-6, 0.3);
    setup.runout_plane2 = probes::spindle_runout(5e-6, 1.1);
    setup.runout_axial = probes::spindle_runout(1e-6, 0.0);
    setup.axial_probe = true;
    // The virtual readings are inputs of the command and part of its result.
    raw = out.path() / "virtual_raw.csv";
    const std::filesystem::path truth = out.path() / "virtual_truth.csv";
    probes::write_virtual_raw_csv(raw, setup, history, truth);
    options.truth_csv = truth;
    options.constants = {};  // the raw file's header carries them
  }
  // 3. Align, recover drift and tilt, compare with the other alignments; publish DIR whole.
  const probes::ProbeRunSummary summary = probes::run_probes_command(raw, out.path(), options);
  out.commit();
  std::cerr << "thermotwin: probes: " << summary.readings << " readings -> " << args.out.string()
            << "\n";
  return 0;
}

}  // namespace tt::app
