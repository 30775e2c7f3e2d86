// thermotwin probes: spindle drift from four non-contact probes (patent CN101628396).
//   thermotwin probes --in RAW.csv --out DIR            recover drift and tilt from raw readings
//   thermotwin probes --from-run RUNDIR --out DIR       the same on a virtual signal made from a
//                                                       finished run's probe points
#include <iostream>

#include "app/commands.hpp"
#include "core/errors.hpp"
#include "core/units.hpp"
#include "io/atomic_dir.hpp"
#include "io/csv_out.hpp"
#include "probes/command.hpp"

namespace tt::app {

namespace {

/// The drift history at a finished run's two axial probe points (its thermal_error.csv, um -> m).
probes::DriftHistory drift_history_from_run(const std::filesystem::path& run_dir) {
  const io::CsvTable te = io::read_numeric_csv(run_dir / "thermal_error.csv");
  const auto metres = [&](Eigen::Index r, const char* column) {
    return core::kMetresPerMicrometre * te.rows(r, te.column_index(column));
  };
  probes::DriftHistory history;
  for (Eigen::Index r = 0; r < te.rows.rows(); ++r) {
    probes::DriftSample s;
    s.time_s = te.rows(r, te.column_index("time_s"));
    s.drift.x1_m = metres(r, "dx_z1_um");
    s.drift.y1_m = metres(r, "dy_z1_um");
    s.drift.x2_m = metres(r, "dx_z2_um");
    s.drift.y2_m = metres(r, "dy_z2_um");
    s.drift.z_m = metres(r, "dz_um");
    history.push_back(s);
  }
  return history;
}

/// A virtual spindle with 5 um runout and 0.1 um noise, read as the command's flags say.
probes::VirtualProbeSetup virtual_probe_setup(const ProbesArgs& args) {
  probes::VirtualProbeSetup setup;
  setup.speed_rpm = args.speed_rpm.value_or(3000.0);
  setup.sample_rate_hz = args.sample_rate_hz.value_or(10000.0);
  setup.probe_distance_m = 1e-3 * args.probe_distance_mm.value_or(70.0);
  setup.runout_plane1 = probes::spindle_runout(5e-6, 0.3);
  setup.runout_plane2 = probes::spindle_runout(5e-6, 1.1);
  setup.runout_axial = probes::spindle_runout(1e-6, 0.0);
  setup.axial_probe = true;
  return setup;
}

}  // namespace

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
    // A finished run's drift read by a virtual spindle's probes: the virtual readings are
    // inputs of the command and part of its result.
    raw = out.path() / "virtual_raw.csv";
    const std::filesystem::path truth = out.path() / "virtual_truth.csv";
    probes::write_virtual_raw_csv(raw, virtual_probe_setup(args),
                                  drift_history_from_run(args.from_run), truth);
    options.truth_csv = truth;
    options.constants = {};  // the raw file's header carries them
  }
  // Align, recover drift and tilt, compare with the other alignments; publish DIR whole.
  const probes::ProbeRunSummary summary = probes::run_probes_command(raw, out.path(), options);
  out.commit();
  std::cerr << "thermotwin: probes: " << summary.readings << " readings -> " << args.out.string()
            << "\n";
  return 0;
}

}  // namespace tt::app
