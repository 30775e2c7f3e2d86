// thermotwin calibrate --case CASE --train RUN... --test RUN... --out DIR [--full] [--no-refit]:
// the model-based side of closing the loop (the study: studies/calibrate_with_model.hpp; the
// files: io/calibration_model_out.hpp). Simulates the declared case under each measured run's
// speed column, finds the undeclared effect that explains the residual, writes the augmented
// case and evaluates it on the test runs.
#include <chrono>
#include <cmath>
#include <iostream>

#include "app/commands.hpp"
#include "core/timing.hpp"
#include "core/units.hpp"
#include "io/atomic_dir.hpp"
#include "io/calibration_model_out.hpp"
#include "io/case_reader.hpp"
#include "io/measured_data.hpp"
#include "io/model_out.hpp"
#include "studies/calibrate_with_model.hpp"

namespace tt::app {

int calibrate_command_with_case(const CalibrateArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  // 1. The declared case and the measured runs.
  studies::ModelCalibrationInput input{
      io::read_case(args.case_file), {}, {}, args.full, !args.no_refit};
  io::require_distinct_runs(args.train, "--train");
  io::require_distinct_runs(args.test, "--test");
  io::require_disjoint_runs(args.test, args.train, "--test", "--train",
                            "calibrate --case does not split a run in time (the data-driven "
                            "calibrate, without --case, does: --split-s); hint: test on a run "
                            "that was not trained on");
  std::vector<std::filesystem::path> inputs = io::case_input_files(input.declared);
  inputs.insert(inputs.end(), args.train.begin(), args.train.end());
  inputs.insert(inputs.end(), args.test.begin(), args.test.end());
  io::OutputDir out(args.out, inputs);  // refused at once, not after the calibration
  for (const auto& f : args.train) input.train.push_back(io::read_measured_run(f));
  for (const auto& f : args.test) input.test.push_back(io::read_measured_run(f));
  // 2. The study, saying what it does.
  const auto say = [&](const std::string& what) {
    if (!args.quiet)
      std::cerr << "thermotwin: calibrate: [" << std::lround(core::seconds_since(t0)) << " s] "
                << what << "\n";
  };
  const solvers::Progress progress = [&](double t, double end) {
    if (!args.quiet) report_progress("calibrate responses", t, end);
  };
  const studies::ModelCalibrationReport report =
      studies::calibrate_with_model(input, say, progress);
  if (report.model.indicator) std::cerr << io::indicator_warning(*report.model.indicator);
  // 3. Outputs, all or nothing.
  io::write_model_calibration(out.path(), report);
  out.commit();
  const calibration::CalibrationResult& res = report.result;
  std::cerr << "thermotwin: calibrate: before T " << res.before.temperature_rms_K << " K, u "
            << res.before.displacement_rms_m * core::kMicrometresPerMetre << " um; after T "
            << res.after.temperature_rms_K << " K, u "
            << res.after.displacement_rms_m * core::kMicrometresPerMetre << " um; "
            << res.effects.size() << " effect(s) -> " << args.out.string() << "\n";
  return 0;
}

}  // namespace tt::app
