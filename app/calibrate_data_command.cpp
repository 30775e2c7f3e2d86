// thermotwin calibrate without --case: close the loop on measured runs alone (the study:
// studies/calibrate_from_data.hpp; the files: io/calibration_data_out.hpp).
//   thermotwin calibrate --train RUN... --test RUN... --out DIR [--split-s T]
// A run given both as --train and --test is split in time: training before T, test from T
// (default: the start of the last speed cycle that begins before 70 % of the run).
#include <iostream>

#include "app/commands.hpp"
#include "io/atomic_dir.hpp"
#include "io/calibration_data_out.hpp"
#include "io/measured_segments.hpp"
#include "studies/calibrate_from_data.hpp"

namespace tt::app {

int calibrate_data_command(const CalibrateArgs& args) {
  std::vector<std::filesystem::path> inputs = args.train;
  inputs.insert(inputs.end(), args.test.begin(), args.test.end());
  io::OutputDir out(args.out, inputs);  // refused at once, not after the study
  const io::SplitRuns runs = io::read_split_runs(args.train, args.test, args.split_s);
  const auto progress = [&](const std::string& line) {
    if (!args.quiet) std::cerr << "thermotwin: calibrate: " << line << "\n";
  };
  const studies::DataCalibrationReport report = studies::calibrate_from_data(
      {runs.training, runs.testing, runs.has_speed, runs.ambient_sensor}, progress);
  io::write_data_calibration(out.path(), report, runs);
  out.commit();
  std::size_t effects = 0;
  for (const auto& ch : report.channels) effects += ch.study.effects.size();
  std::cerr << "thermotwin: calibrate: test RMS " << report.rms_before * 1e6 << " -> "
            << report.rms_after * 1e6 << " um, " << effects << " effects\n";
  return 0;
}

}  // namespace tt::app
