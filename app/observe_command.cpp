// thermotwin observe CASE --rom DIR --data RUN --out DIR: the physics observer (docs/observer.md)
// on a measured run: a Kalman filter on the reduced model's states, fed with the run's spindle
// speed (its speed_rpm column) as the duty cycle and its sensors' readings, that predicts the
// drift at the tool (and the axis points) with its standard deviation and says when the
// innovations stop fitting the noise model (status `recalibrate`, with the time it started).
//   1. the case and the run, the output claimed;
//   2. the reduced model, checked against the case and its mesh;
//   3. the study (studies/observe_run.hpp): the case under the run's inputs, the sensors
//      (--sensors, default: every sensor of the run that is a named point of the model), the
//      observer's set-up (app/observer_options.hpp), the run through the filter;
//   4. observer.csv and observer.json (io/observe_out.hpp), all or nothing.
#include <iostream>
#include <string>

#include "app/commands.hpp"
#include "app/observer_options.hpp"
#include "io/atomic_dir.hpp"
#include "io/case_reader.hpp"
#include "io/measured_data.hpp"
#include "io/observe_out.hpp"
#include "io/reduced_model_io.hpp"
#include "mesh/mesher.hpp"
#include "studies/observe_run.hpp"

namespace tt::app {

int observe_command(const ObserveArgs& args) {
  // 1. The case and the run.
  const core::CaseSpec declared = io::read_case(args.case_file);
  const io::MeasuredRun run = io::read_measured_run(args.data);
  std::vector<std::filesystem::path> inputs = io::case_input_files(declared);
  inputs.insert(inputs.end(), {args.rom, args.data});
  io::OutputDir out(args.out, inputs);
  // 2. The reduced model, built for this machine and mesh.
  const io::ReducedModelFile rom = io::read_reduced_model(args.rom);
  const mesh::TetMesh mesh = mesh::mesh_case(declared);
  io::check_reduced_model_fits(rom, io::reduced_model_key(declared, mesh), args.rom);
  // 3. The study: the run's sensors read at their positions where it gives them.
  const auto setup = [&](const core::CaseSpec& spec, const std::vector<std::string>& sensors,
                         const Eigen::MatrixXd& rows) {
    return observer_setup(args.observer, rom.twin, spec, sensors, rows);
  };
  const studies::ObserveReport report =
      studies::observe_run({&declared, &run, &rom.twin, args.observer.sensors, setup, &mesh,
                            args.observer.drift_readings_every_s});
  // 4. Outputs.
  io::write_observe(out.path(), report,
                    {run.run, declared.name, rom.twin.model.states(), args.rom,
                     observer_noise_json(report.setup)});
  out.commit();
  const solvers::ObserverRun& r = report.result;
  // A faulty sensor is a warning, written even with --quiet.
  for (const solvers::HeldSensor& f : r.sensor_faults)
    std::cerr << "thermotwin: observe: warning: sensor "
              << report.sensors[static_cast<std::size_t>(f.sensor)]
              << " reads off by an offset (observer.json sensor_faults) since t = " << f.since_s
              << " s: check its mounting and calibration\n";
  if (args.quiet) return 0;
  std::cerr << "thermotwin: observe: " << r.times.size() << " samples, status "
            << (r.recalibrate
                    ? "recalibrate since t = " + std::to_string(r.recalibrate_since_s) + " s"
                    : std::string(r.sensor_faults.empty() ? "ok" : "sensor_fault"))
            << "\n";
  for (const solvers::HeldSensor& d : r.model_departures)
    std::cerr << "thermotwin: observe: sensor "
              << report.sensors[static_cast<std::size_t>(d.sensor)]
              << " read away from the declared model's run since t = " << d.since_s
              << " s, beginning near t = " << d.onset_s << " s (observer.json model_departures)\n";
  for (const solvers::HeldSensor& d : r.drift_departures)
    std::cerr << "thermotwin: observe: the drift readings of "
              << report.setup.target_names[static_cast<std::size_t>(d.sensor)]
              << " departed from the model since t = " << d.since_s
              << " s (observer.json drift_readings)\n";
  return 0;
}

}  // namespace tt::app
