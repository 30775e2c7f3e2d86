// thermotwin fit --data: thermal-error models fitted on measured runs with no machine model behind
// them (DB3401/T 326-2024 metrics S, S_M, S_sigma, and the error on held-out data).
//   thermotwin fit --data RUN... --out DIR [--test RUN... | --test-from-s T0 --test-to-s T1]
//                  [--quick] [--network]
// Any run shape: with or without a speed input, one long run or many short ones, days as runs.
// The held-out data and the cutting: io/fit_data_in.hpp; the study: studies/fit_from_data.hpp;
// the files (fit.json, summary.md, compensation.csv, window_<channel>.csv/.png in window mode):
// io/fit_data_out.hpp.
#include <iostream>

#include "app/commands.hpp"
#include "io/atomic_dir.hpp"
#include "io/fit_data_in.hpp"
#include "io/fit_data_out.hpp"
#include "studies/fit_from_data.hpp"

namespace tt::app {

int fit_data_command(const FitDataArgs& args) {
  std::vector<std::filesystem::path> inputs = args.runs;
  inputs.insert(inputs.end(), args.test_runs.begin(), args.test_runs.end());
  io::OutputDir out(args.out, inputs);  // refused at once, not after the study
  const io::DataFitRuns runs =
      io::read_data_fit_runs(args.runs, args.test_runs, args.test_from_s, args.test_to_s);
  const auto progress = [&](const studies::DataFitReport& so_far) {
    if (!args.quiet)
      std::cerr << "thermotwin: fit --data: " << io::data_fit_progress(so_far) << "\n";
  };
  const studies::DataFitReport report = studies::fit_from_data(
      {runs.training_pieces, runs.testing, runs.windowed_run, runs.from_s, runs.to_s,
       runs.training_runs, runs.has_speed, args.quick, args.network},
      progress);
  io::write_data_fit(out.path(), report, runs);
  out.commit();
  return 0;
}

}  // namespace tt::app
