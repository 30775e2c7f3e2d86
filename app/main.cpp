// thermotwin: the command-line driver. Each command reads its flags and inputs, runs, and writes
// one output directory (README.md "Commands" lists every file it holds):
//   mesh CASE --out DIR            the mesh: mesh.vtu, boundary.vtp, points.vtp, mesh_report.json
//   run CASE --out DIR             the simulation: fields.pvd, temperatures.csv, thermal_error.csv,
//                                  summary.json (with --rom DIR, from a reduced model)
//   reduce CASE --out DIR          the reduced-order twin, validated against the full model
//   place CASE --out DIR           sensor placement (or --from RUNDIR): placement.json
//   fit CASE --out DIR             error models on a virtual campaign: fit.json, modelling record;
//                                  with --data RUN... instead of CASE, on measured runs
//   calibrate --case CASE --train RUN... --test RUN... --out DIR
//                                  what the model lacks on measured runs, before and after;
//                                  without --case, from the data alone
//   probes --in RAW.csv --out DIR  spindle drift and tilt from four non-contact probes
//   compensate --model FIT.json    live drift per sensor sample (stdin or a growing file); with
//                                  --rom DIR instead, through the physics observer
//   export --model FIT.json --out DIR
//                                  the compensation in SINUMERIK, TwinCAT, Heidenhain, LinuxCNC
//                                  form
//   observe CASE --rom DIR --data RUN --out DIR
//                                  the physics observer: drift with its sigma, recalibrate status
//                                  (--train RUN...: its sigma calibrated on measured drift;
//                                  --changed RUN...: c and e chosen on a changed machine)
//   --version                      the version, and git describe of the source it was built from
// Errors print one line on stderr and exit non-zero; no partial output directory is left. --out
// replaces only an earlier result of thermotwin (docs/reliability.md), one command at a time.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "app/cli_numbers.hpp"
#include "app/commands.hpp"
#include "app/observer_options.hpp"
#include "app/version.hpp"
#include "core/errors.hpp"
#include "io/atomic_dir.hpp"
#include "solvers/cholmod/cholmod_factor.hpp"

namespace {

using namespace tt::app;

/// A subcommand and what runs it once the command line is parsed (its arguments checked there).
struct Command {
  CLI::App* subcommand;
  std::function<int()> run;
};

/// `mesh CASE --out DIR`.
Command mesh_line(CLI::App& cli) {
  auto args = std::make_shared<MeshArgs>();
  MeshArgs& mesh_args = *args;
  auto* mesh =
      cli.add_subcommand("mesh", "Mesh a case and write the mesh, its boundary and named points");
  mesh->add_option("case", mesh_args.case_file, "case file (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  mesh->add_option("--out", mesh_args.out, "output directory")->required();
  return {mesh, [args] {
            const MeshArgs& a = *args;
            return mesh_command(a);
          }};
}

/// `run CASE --out DIR`.
Command run_line(CLI::App& cli) {
  auto args = std::make_shared<RunArgs>();
  RunArgs& run_args = *args;
  auto* run =
      cli.add_subcommand("run", "Simulate a case: heat transfer, thermo-elasticity, thermal error");
  run->add_option("case", run_args.case_file, "case file (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  run->add_option("--out", run_args.out, "output directory")->required();
  run->add_flag("--quiet", run_args.quiet, "no progress on stderr");
  run->add_flag("--resume", run_args.resume,
                "continue from OUT.checkpoint, left by an interrupted run");
  run->add_option("--checkpoint-every-s", run_args.checkpoint_every_s,
                  "wall time between checkpoints of the time loop (default 600; negative: none)")
      ->check(finite_number());
  run->add_option(
         "--rom", run_args.rom,
         "a reduced model (thermotwin reduce CASE --out DIR): the thermal transient from it")
      ->check(CLI::ExistingDirectory);
  run->add_flag("--verify", run_args.verify,
                "with --rom: recompute the output times with the full model and report the "
                "difference in summary.json");
  // Hidden (empty group): for the reliability tests.
  run->add_option("--duty-cycle", run_args.duty_cycle,
                  "another duty cycle for the case: CSV \"time_s,speed_rpm\" (a row per speed "
                  "change, the first at 0), instead of its [duty_cycle]")
      ->check(CLI::ExistingFile);
  run->add_option("--end-s", run_args.end_s,
                  "with --duty-cycle: the run's end [s] (default: the case's duty_cycle.end_s)")
      ->check(positive_number());
  run->add_option("--stop-after-steps", run_args.stop_after_steps)->group("");
  run->add_option("--dump", run_args.dump)->group("");
  return {run, [args] {
            const RunArgs& a = *args;
            return run_command(a);
          }};
}

/// `reduce CASE --out DIR`.
Command reduce_line(CLI::App& cli) {
  auto args = std::make_shared<ReduceArgs>();
  ReduceArgs& reduce_args = *args;
  auto* reduce = cli.add_subcommand(
      "reduce", "Build the reduced-order twin of a case and validate it against the full model");
  reduce->add_option("case", reduce_args.case_file, "case file (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  reduce->add_option("--out", reduce_args.out, "output directory")->required();
  reduce->add_flag("--quick-validation", reduce_args.quick_validation,
                   "validate on the case's own duty cycle only (default: three more cycles)");
  reduce->add_flag("--quiet", reduce_args.quiet, "no progress on stderr");
  return {reduce, [args] {
            const ReduceArgs& a = *args;
            return reduce_command(a);
          }};
}

/// `probes --in RAW.csv | --from-run RUNDIR --out DIR`.
Command probes_line(CLI::App& cli) {
  auto args = std::make_shared<ProbesArgs>();
  ProbesArgs& probes_args = *args;
  auto* probes =
      cli.add_subcommand("probes", "Spindle drift and tilt from four non-contact probes");
  auto* probes_in =
      probes->add_option("--in", probes_args.in, "raw probe readings (CSV, see docs/probes.md)")
          ->check(CLI::ExistingFile);
  auto* probes_run =
      probes
          ->add_option("--from-run", probes_args.from_run,
                       "make a virtual probe signal from a finished run's probe points")
          ->check(CLI::ExistingDirectory);
  probes_in->excludes(probes_run);
  probes->add_option("--out", probes_args.out, "output directory")->required();
  probes->add_option("--truth", probes_args.truth, "true drift CSV to score the methods against");
  probes
      ->add_option("--speed-rpm", probes_args.speed_rpm,
                   "measuring speed when the file does not say")
      ->check(positive_number());
  probes
      ->add_option("--sample-rate-hz", probes_args.sample_rate_hz,
                   "sample rate when the file does not say")
      ->check(positive_number());
  probes
      ->add_option("--probe-distance-mm", probes_args.probe_distance_mm,
                   "D when the file does not say")
      ->check(positive_number());
  return {probes, [args] {
            const ProbesArgs& a = *args;
            if (a.in.empty() && a.from_run.empty())
              throw tt::core::DataError("probes: give --in RAW.csv or --from-run RUNDIR");
            return probes_command(a);
          }};
}

/// `place CASE --out DIR` or `place --from RUNDIR --out DIR`.
Command place_line(CLI::App& cli) {
  auto args = std::make_shared<PlaceArgs>();
  PlaceArgs& place_args = *args;
  auto* place = cli.add_subcommand(
      "place", "Sensor placement: the patent's MI + GA method and stronger criteria");
  auto* place_case =
      place->add_option("case", place_args.case_file, "case file (TOML)")->check(CLI::ExistingFile);
  auto* place_from =
      place->add_option("--from", place_args.from_run, "a finished run directory instead of a case")
          ->check(CLI::ExistingDirectory);
  place_case->excludes(place_from);
  place->add_option("--out", place_args.out, "output directory")->required();
  place->add_option("--samples", place_args.samples,
                    "S, samples the histories are resampled to (patent: 100)");
  place->add_option("--bins", place_args.bins, "N = M, histogram bins (patent: 20 to 40)");
  place->add_option("--m-max", place_args.m_max, "largest number of sensors");
  place->add_flag("--sensor-noise", place_args.sensor_noise,
                  "place on readings as real sensors give them: the campaign's noise (0.05 K, "
                  "0.01 K resolution; 0.3 um on the error), seeded by the case");
  place->add_flag("--quiet", place_args.quiet, "no progress on stderr");
  auto* detection_flag = place->add_flag(
      "--catalogue-detection", place_args.catalogue_detection,
      "also place for detection of the calibration catalogue's effects (a heat input "
      "on any patch of the surface, films, sources, materials, the air): where each "
      "would move a reading 3 sigma for 900 s (placement.json catalogue_detection, "
      "docs/placement.md)");
  const std::pair<const char*, std::optional<double>*> sizes[] = {
      {"--detect-heat-w", &place_args.detect_heat_w},
      {"--detect-film-share", &place_args.detect_film_share},
      {"--detect-source-per-k", &place_args.detect_source_per_k},
      {"--detect-material-change", &place_args.detect_material_change},
      {"--detect-air-k", &place_args.detect_air_k}};
  const char* size_help[] = {
      "with --catalogue-detection: a heat input's power on its patch [W] (default 5)",
      "with --catalogue-detection: a film's change, or its growth with speed, as a share of its "
      "declared coefficient (default 0.25)",
      "with --catalogue-detection: a source's heat growing with its temperature [1/K] (default "
      "0.02)",
      "with --catalogue-detection: a conductivity's or heat capacity's relative change (default "
      "0.1)",
      "with --catalogue-detection: the air's offset over the run [K] (default 1)"};
  for (std::size_t k = 0; k < std::size(sizes); ++k)
    place->add_option(sizes[k].first, *sizes[k].second, size_help[k])
        ->check(positive_number())
        ->needs(detection_flag);
  place
      ->add_option("--methods", place_args.methods,
                   "placement methods, comma-separated (default: all but observer_variance, the "
                   "physics observer's posterior variance, which needs the reduced model)")
      ->delimiter(',');
  place
      ->add_option("--rom", place_args.rom,
                   "a reduced model (thermotwin reduce CASE --out DIR) to simulate the case on")
      ->check(CLI::ExistingDirectory);
  place->add_flag("--full", place_args.full,
                  "simulate in full order (default: a reduced model built on the fly)");
  return {place, [args] {
            const PlaceArgs& a = *args;
            if (a.case_file.empty() && a.from_run.empty())
              throw tt::core::CaseError("place: give a case file or --from RUNDIR");
            return place_command(a);
          }};
}

/// fit's options that only fit --data reads: the test window and the held-out runs.
void add_fit_data_options(CLI::App& fit, FitDataArgs& args, CLI::Option* fit_case) {
  auto* data =
      fit.add_option("--data", args.runs, "measured runs (docs/measured-data.md) instead of a case")
          ->check(CLI::ExistingDirectory);
  fit_case->excludes(data);
  fit.add_option("--test-from-s", args.test_from_s,
                 "with --data: test window start (default: published)")
      ->check(finite_number());
  fit.add_option("--test-to-s", args.test_to_s, "with --data: test window end")
      ->check(finite_number());
  fit.add_option("--test", args.test_runs, "with --data: held-out measured runs, tested whole")
      ->check(CLI::ExistingDirectory);
}

/// `fit CASE --out DIR` or `fit --data RUN... --out DIR`.
Command fit_line(CLI::App& cli) {
  auto args = std::make_shared<FitArgs>();
  auto data_args = std::make_shared<FitDataArgs>();
  FitArgs& fit_args = *args;
  auto* fit = cli.add_subcommand(
      "fit", "Thermal-error models on placed sensors, judged on held-out duty cycles");
  auto* fit_case =
      fit->add_option("case", fit_args.case_file, "case file (TOML)")->check(CLI::ExistingFile);
  add_fit_data_options(*fit, *data_args, fit_case);
  fit->add_option("--out", fit_args.out, "output directory")->required();
  fit->add_option("--hours", fit_args.hours,
                  "length of each campaign run (the standard's minimum: 5)")
      ->check(positive_number());
  fit->add_option("--required-sm-um", fit_args.required_sm_um,
                  "accuracy asked for: smallest m with test S_M below it")
      ->check(positive_number());
  fit->add_flag("--quick", fit_args.quick,
                "least squares only (no model search); with --data: a coarser ridge grid");
  fit->add_flag("--network", fit_args.network,
                "also try the CNN-BiGRU-attention network (seed 004); writes network_<target>.pt "
                "(and network_all_outputs.pt, one network for every output, on a case with "
                "feed-axis points)");
  fit->add_flag("--quiet", fit_args.quiet, "no progress on stderr");
  fit->add_option("--rom", fit_args.rom,
                  "a reduced model (thermotwin reduce CASE --out DIR) to run the campaign on")
      ->check(CLI::ExistingDirectory);
  auto* full =
      fit->add_flag("--full", fit_args.full,
                    "the campaign in full order (default: a reduced model built on the fly)");
  fit->add_flag("--estimation", fit_args.estimation,
                "also place for estimation (observer_variance: the physics observer's posterior "
                "variance of the drift over the fitting runs' duty cycles) on the campaign's "
                "reduced model; costs minutes on a model of several hundred states")
      ->excludes(full);
  return {fit, [args, data_args] {
            if (!data_args->runs.empty()) {
              FitDataArgs d = *data_args;
              d.out = args->out;
              d.quick = args->quick;
              d.network = args->network;
              d.quiet = args->quiet;
              return fit_data_command(d);
            }
            if (args->case_file.empty())
              throw tt::core::CaseError("fit: give a case file or --data RUN...");
            return fit_command(*args);
          }};
}

/// `calibrate [--case CASE] --train RUN... --test RUN... --out DIR`.
Command calibrate_line(CLI::App& cli) {
  auto args = std::make_shared<CalibrateArgs>();
  CalibrateArgs& calibrate_args = *args;
  auto* calibrate = cli.add_subcommand(
      "calibrate", "Close the loop on measured runs: what the model lacks, before/after");
  calibrate
      ->add_option("--case", calibrate_args.case_file, "case file (TOML): the model-based path")
      ->check(CLI::ExistingFile);
  calibrate->add_option("--train", calibrate_args.train, "measured runs to fit and study on")
      ->check(CLI::ExistingDirectory);
  calibrate->add_option("--test", calibrate_args.test, "held-out measured runs")
      ->check(CLI::ExistingDirectory);
  calibrate
      ->add_option("--split-s", calibrate_args.split_s,
                   "a run in both --train and --test: train before, test from")
      ->check(finite_number());
  calibrate->add_option("--out", calibrate_args.out, "output directory")->required();
  calibrate->add_flag("--full", calibrate_args.full,
                      "with --case: march the full-order model (default: a reduced model built on "
                      "the runs' channels)");
  calibrate->add_flag("--no-refit", calibrate_args.no_refit,
                      "with --case: keep the claims' linearised sizes (default: refitted about the "
                      "updated model by Gauss-Newton where that predicts held-out runs better: "
                      "docs/calibration.md)");
  calibrate->add_flag("--quiet", calibrate_args.quiet, "no progress on stderr");
  return {calibrate, [args] {
            const CalibrateArgs& a = *args;
            if (a.case_file.empty() && a.no_refit)
              throw tt::core::CaseError(
                  "calibrate: --no-refit concerns the claims on the model of "
                  "--case; "
                  "without --case there is no model. Hint: give --case CASE");
            if (a.case_file.empty() && a.full)
              throw tt::core::CaseError(
                  "calibrate: --full chooses the model of calibrate --case; without "
                  "--case there is no model to reduce. Hint: drop --full or give "
                  "--case CASE");
            return a.case_file.empty() ? calibrate_data_command(a) : calibrate_command_with_case(a);
          }};
}

/// compensate's input and output stream options: --in, --out, --until-eof, --idle-s, --poll-ms,
/// --flush, --max-behind-mib, --column.
void add_stream_options(CLI::App& compensate, CompensateArgs& compensate_args) {
  auto* compensate_in = compensate.add_option(
      "--in", compensate_args.in, "CSV samples (default: standard input); followed as it grows");
  compensate.add_option("--out", compensate_args.out, "output CSV (default: standard output)");
  auto* until_eof = compensate
                        .add_flag("--until-eof", compensate_args.until_eof,
                                  "with --in: stop at the file's end, do not follow it")
                        ->needs(compensate_in);
  compensate
      .add_option("--idle-s", compensate_args.idle_s,
                  "with --in: stop when the file has not grown for this long [s]")
      ->check(positive_number())
      ->excludes(until_eof)
      ->needs(compensate_in);
  compensate
      .add_option("--poll-ms", compensate_args.poll_ms,
                  "with --in: how often to look for new lines at its end [ms] (default 5)")
      ->check(CLI::Range(1, 10000))
      ->needs(compensate_in);
  compensate.add_flag("--flush", compensate_args.flush,
                      "flush after every line (default: when the input pauses; always on a "
                      "terminal)");
  compensate
      .add_option("--max-behind-mib", compensate_args.max_behind_mib,
                  "output held for a reader that falls behind [MiB]: compensate never waits for "
                  "its reader; beyond this the lines not yet written are dropped and the next "
                  "line's status says dropped:N (default 16)")
      ->check(positive_number());
  compensate.add_option("--column", compensate_args.columns,
                        "MODEL=STREAM: read the stream's column STREAM as the model's sensor or "
                        "input MODEL (a logger's own names, e.g. speed_rpm=spindle_rpm); "
                        "repeatable. Statuses name the stream's columns");
}

/// `compensate --model FIT.json | --rom DIR`.
Command compensate_line(CLI::App& cli) {
  auto args = std::make_shared<CompensateArgs>();
  CompensateArgs& compensate_args = *args;
  auto* compensate = cli.add_subcommand(
      "compensate",
      "Live compensation: drift per sample from a fitted model or, through the physics observer, "
      "a reduced model (docs/compensate.md)");
  auto* compensate_model =
      compensate
          ->add_option("--model", compensate_args.model, "fit.json of thermotwin fit or fit --data")
          ->check(CLI::ExistingFile);
  auto* compensate_rom =
      compensate
          ->add_option("--rom", compensate_args.rom,
                       "a reduced model (thermotwin reduce CASE --out DIR): the physics observer")
          ->check(CLI::ExistingDirectory)
          ->excludes(compensate_model);
  compensate_model->excludes(compensate_rom);
  compensate
      ->add_option("--case", compensate_args.case_file,
                   "with --rom: the case it was built from (default: the one it records)")
      ->check(CLI::ExistingFile)
      ->needs(compensate_rom);
  compensate
      ->add_option("--initial-temperature-c", compensate_args.initial_temperature_c,
                   "with --rom: the machine's uniform temperature at t = 0 [degC] (default: the "
                   "case's)")
      ->check(finite_number())
      ->needs(compensate_rom);
  compensate
      ->add_option("--meta", compensate_args.meta,
                   "with --rom: the recorded run's meta.json; its sensors are read at their "
                   "positions (not only at named points of the model), its "
                   "initial_temperature_degC is the machine's at t = 0 unless "
                   "--initial-temperature-c says otherwise")
      ->check(CLI::ExistingFile)
      ->needs(compensate_rom);
  compensate
      ->add_option("--filter-every-s", compensate_args.filter_every_s,
                   "with --rom: the observer's period [s]: the samples of a period are assimilated "
                   "as one reading, their mean, at its last sample, and the speed over it is "
                   "their time mean; samples further apart are each assimilated (default 1; 0: "
                   "every sample)")
      ->check(non_negative_number())
      ->needs(compensate_rom);
  compensate
      ->add_option("--network-every-s", compensate_args.network_every_s,
                   "with --model: a network (cnn_bigru_attention) is evaluated at a sample at "
                   "least this long after its last evaluation [s] and its prediction held between "
                   "(default 1; 0: every sample)")
      ->check(non_negative_number())
      ->needs(compensate_model);
  compensate
      ->add_flag("--time-from-first-sample", compensate_args.from_first_sample,
                 "with --rom: the stream's first sample is the model's t = 0, a cold start at the "
                 "initial temperature, whatever its time_s (a clock's time); default: time_s is "
                 "the time since the run's start, as in a recorded run")
      ->needs(compensate_rom);
  // The observer's options need a reduced model: with a fitted model they would be ignored.
  const std::size_t before_observer = compensate->get_options().size();
  add_observer_options(*compensate, compensate_args.observer);
  const std::vector<CLI::Option*> options = compensate->get_options();
  for (std::size_t k = before_observer; k < options.size(); ++k) options[k]->needs(compensate_rom);
  add_stream_options(*compensate, compensate_args);
  return {compensate, [args] {
            const CompensateArgs& a = *args;
            if (a.model.empty() == a.rom.empty())
              throw tt::core::DataError(
                  "compensate: give a fitted model (--model FIT.json) or a reduced "
                  "model (--rom DIR), one of the two");
            return compensate_command(a);
          }};
}

/// `export --model FIT.json --out DIR`.
Command export_line(CLI::App& cli) {
  auto args = std::make_shared<ExportArgs>();
  ExportArgs& export_args = *args;
  auto* exporter = cli.add_subcommand(
      "export",
      "The compensation in the CNC's own formats, with the error of each controller's "
      "law (docs/cnc-export.md)");
  exporter->add_option("--model", export_args.model, "fit.json of thermotwin fit")
      ->required()
      ->check(CLI::ExistingFile);
  exporter->add_option("--format", export_args.formats,
                       "sinumerik, twincat, heidenhain or linuxcnc (repeatable; default: all)");
  exporter->add_option("--out", export_args.out, "output directory")->required();
  exporter
      ->add_option("--states", export_args.states,
                   "CSV of sensor samples (time_s, sensor ids): temperature states the laws "
                   "are judged on (repeatable, e.g. fit's held_out/*_temperatures.csv)")
      ->check(CLI::ExistingFile);
  exporter
      ->add_option("--table-points", export_args.table_points,
                   "entries of the TwinCAT and Heidenhain tables over the travel (default 51)")
      ->check(CLI::Range(2, 100000));
  exporter
      ->add_option("--grid", export_args.grid,
                   "positions over the travel where the laws are judged (default 1001)")
      ->check(CLI::Range(2, 1000000));
  return {exporter, [args] {
            const ExportArgs& a = *args;
            return export_command(a);
          }};
}

/// `observe CASE --rom DIR --data RUN --out DIR`.
Command observe_line(CLI::App& cli) {
  auto args = std::make_shared<ObserveArgs>();
  ObserveArgs& observe_args = *args;
  auto* observe = cli.add_subcommand("observe",
                                     "Physics observer on a measured run: a Kalman filter on the "
                                     "reduced model (docs/observer.md)");
  observe->add_option("case", observe_args.case_file, "case file (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  observe
      ->add_option("--rom", observe_args.rom,
                   "the reduced model (thermotwin reduce CASE --out DIR)")
      ->required()
      ->check(CLI::ExistingDirectory);
  observe->add_option("--data", observe_args.data, "measured run folder (meta.json, data.csv)")
      ->check(CLI::ExistingDirectory);
  auto* train = observe
                    ->add_option("--train", observe_args.train,
                                 "measured runs whose drift was measured throughout (columns "
                                 "named after targets: dx, dy, dz, ...): calibrate the factors on "
                                 "the reported drift sigma on them (OUT/sigma_calibration.json) "
                                 "and use them on --data")
                    ->check(CLI::ExistingDirectory);
  auto* changed =
      observe
          ->add_option("--changed", observe_args.changed,
                       "with --train: measured runs of the machine changed (an effect the "
                       "declared model lacks), their drift measured as the training runs' is: "
                       "choose --correction-relative-sigma and --expansion-relative-sigma on them "
                       "(sigma_calibration.json changed_machine; docs/observer.md)")
          ->check(CLI::ExistingDirectory)
          ->needs(train);
  observe
      ->add_flag("--choose-evidence", observe_args.choose_evidence,
                 "with --changed and --changed-terms-on-evidence: also choose --evidence-time-s "
                 "and --evidence-onset-sigmas on the changed runs (the setting whose pair comes "
                 "nearest the coverage with the narrowest band on the training runs; "
                 "changed_machine.evidence_settings)")
      ->needs(changed);
  observe
      ->add_option("--truth-sigma-um", observe_args.truth_sigma_um,
                   "with --train: white noise of the measured drift [um]: declared, the factor "
                   "is the coverage rule's on the measured drift averaged over 300 s, which "
                   "divides that noise (default 0: the noise counted as error, which errs wide; "
                   "docs/observer.md)")
      ->check(non_negative_number())
      ->needs(train);
  observe
      ->add_option("--coverage", observe_args.coverage,
                   "with --train: the share of training samples the ±2 sigma band is to hold "
                   "(default 0.95)")
      ->check(CLI::Range(0.5, 0.9999))
      ->needs(train);
  observe->add_option("--out", observe_args.out, "output directory")->required();
  add_observer_options(*observe, observe_args.observer);
  observe->add_flag("--quiet", observe_args.quiet, "no summary on stderr");
  return {observe, [args] {
            const ObserveArgs& a = *args;
            if (a.data.empty() && a.train.empty())
              throw tt::core::DataError(
                  "observe: give a run to observe (--data RUN), training runs to calibrate the "
                  "sigma on (--train RUN ...), or both");
            return observe_command(a);
          }};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"thermotwin: thermal twin of a machine tool"};
  cli.require_subcommand(1);
  const std::string git = tt::app::kGitDescribe;
  cli.set_version_flag("--version", std::string("thermotwin ") + tt::app::kVersion +
                                        (git.empty() ? "" : " (git " + git + ")"));

  const std::vector<Command> commands{mesh_line(cli),      run_line(cli),        reduce_line(cli),
                                      probes_line(cli),    place_line(cli),      fit_line(cli),
                                      calibrate_line(cli), compensate_line(cli), export_line(cli),
                                      observe_line(cli)};

  CLI11_PARSE(cli, argc, argv);
  // Two settings that the libraries read only when they are loaded, so the program starts again,
  // once, with them set (a value the user set is kept; if exec fails, go on):
  // - OpenBLAS chose kernels slower than this CPU allows (cholmod_factor.hpp, better_blas_core):
  //   OPENBLAS_CORETYPE.
  // - OMP_WAIT_POLICY=passive: between the many short parallel regions of the reduced basis's
  //   dense products, an idle OpenMP thread otherwise spins; on the shared 2-core machine that
  //   was 17 % of the samples of a GM-1 coarse twin build, and the build used 10 to 20 % less CPU
  //   time without it (docs/benchmarks.md).
  bool again = false;
  if (!std::getenv("OPENBLAS_CORETYPE")) {
    const std::string core = tt::solvers::cholmod::better_blas_core();
    again = !core.empty() && setenv("OPENBLAS_CORETYPE", core.c_str(), 1) == 0;
  }
  if (!std::getenv("OMP_WAIT_POLICY"))
    again = setenv("OMP_WAIT_POLICY", "passive", 1) == 0 || again;
  if (again) execv("/proc/self/exe", argv);
  // Ctrl-C or a kill (SIGINT, SIGTERM, SIGHUP) while a command works removes its DIR.partial and
  // DIR.lock; DIR keeps the previous result and DIR.checkpoint stays for --resume.
  tt::io::clean_up_outputs_on_signals();
  // BLAS threads: TT_BLAS_THREADS, default 1 (see set_blas_threads).
  const char* blas = std::getenv("TT_BLAS_THREADS");
  tt::solvers::cholmod::set_blas_threads(blas ? std::max(1, std::atoi(blas)) : 1);
  try {
    for (const auto& command : commands)
      if (*command.subcommand) return command.run();
  } catch (const tt::core::Error& e) {
    std::cerr << "thermotwin: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "thermotwin: unexpected error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
