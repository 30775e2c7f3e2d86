// The observer's sigma calibrated as `observe --train` calibrates it (studies::
// calibrate_observer_sigma), judged on held-out runs of the calibration generator: the ±2 sigma
// band's coverage of the true drift and of the measured one, before (the observer's own sigma)
// and after (times the calibrated factor), on clean held-out runs and on runs with an undeclared
// effect (one of each kind of the generator's catalogue). The reference is the uncalibrated
// sigma of the same runs, measured in the same run of the bench. A second draw of one run of each
// kind plays the changed-machine runs (observe --changed) that choose the correction's and the
// expansion's relative sigma; the held-out runs are scored with them too. (With c and e the
// "uncalibrated" column is the factors' alone, c = e = 0.)
//
//   bench_studies_observer_sigma CASE SENSORS TRAIN HELD HOURS SEED [PROBE_EVERY_S]
//
// SENSORS: comma-separated named points the generator reads and the observer reads; TRAIN and
// HELD: how many clean runs train and are held out; HOURS: each run's random duty cycle;
// PROBE_EVERY_S > 0: also a probe cycle (the runs' TCP probes read every so often, their noise
// declared: --drift-reading-sigma-um 0.08), its own factors, scored between its readings. The
// training runs' probes carry the generator's 0.08 um noise, declared as --truth-sigma-um declares
// it (and, beside it, not declared).
#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "calibration/effects.hpp"
#include "calibration/generator.hpp"
#include "calibration/model.hpp"
#include "core/rng.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"
#include "solvers/observer.hpp"
#include "solvers/twin.hpp"
#include "studies/observer_sigma.hpp"

namespace {

using namespace tt;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream s(text);
  for (std::string item; std::getline(s, item, ',');) out.push_back(item);
  return out;
}

/// The command line's noise model (app/observer_options: ObserverOptions' defaults), set where
/// it differs from solvers::ObserverNoise's (the walks of heat and air are the same).
solvers::ObserverSetup cli_setup(const solvers::Twin& twin, const core::CaseSpec& spec,
                                 const std::vector<std::string>& sensors,
                                 const Eigen::MatrixXd& rows, const Eigen::VectorXd& scale) {
  solvers::ObserverNoise n;
  n.sensor_sigma_k = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(sensors.size()), 0.05);
  n.sensor_offset_initial_k = 0.5;
  n.sensor_offset_walk_k = 0.05;
  n.drift_relative_sigma = 0.04;
  n.drift_reading_sigma_m = 0.08e-6;  // the generator's probes, as a user declares them
  solvers::ObserverSetup s = solvers::twin_observer_setup(twin, spec, sensors, n, rows);
  s.noise.drift_sigma_scale = scale;
  return s;
}

/// A generated run: what the sensors and probes read, and the true drift (noise-free).
struct Generated {
  std::string kind;
  io::MeasuredRun measured;
  Eigen::MatrixXd truth;  /// #samples x the observer's targets [m], NaN where not known
};

/// The coverage of held-out runs, pooled: per target before and after.
struct Pooled {
  std::vector<solvers::ObserverRun> runs;
  std::vector<Eigen::MatrixXd> truths, measured;
};

void report(const std::string& what, const Pooled& p, const Eigen::VectorXd& factor, double noise_m,
            const std::vector<std::string>& targets) {
  if (p.runs.empty()) return;
  const auto before = solvers::drift_band_score(p.runs, p.truths);
  const auto after = solvers::drift_band_score(p.runs, p.truths, factor);
  const auto measured_after = solvers::drift_band_score(p.runs, p.measured, factor, noise_m);
  for (std::size_t t = 0; t < targets.size(); ++t) {
    const auto k = static_cast<Eigen::Index>(t);
    if (before.samples(k) == 0) continue;
    std::printf("%s | %s | %d | %.4f | %.1f %% | %.1f %% | %.1f %% | %.3f | %.2f\n", what.c_str(),
                targets[t].c_str(), before.samples(k), 1e6 * before.rms_error_m(k),
                100 * before.coverage(k), 100 * after.coverage(k), 100 * measured_after.coverage(k),
                factor(k), after.rms_sigma_m(k) / after.rms_error_m(k));
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 7) {
      std::cerr << "usage: bench_studies_observer_sigma CASE SENSORS TRAIN HELD HOURS SEED "
                   "[PROBE_EVERY_S]\n";
      return 2;
    }
    const auto t_all = Clock::now();
    const core::CaseSpec spec = io::read_case(argv[1]);
    const std::vector<std::string> sensors = split(argv[2]);
    const int train = std::stoi(argv[3]), held = std::stoi(argv[4]);
    const double hours = std::stod(argv[5]);
    const auto seed = static_cast<std::uint64_t>(std::stoull(argv[6]));
    const double probe_every_s = argc > 7 ? std::stod(argv[7]) : 0;
    const mesh::TetMesh mesh = mesh::mesh_case(spec);
    const solvers::FullThermalSystem full = solvers::thermal_system(mesh, spec);
    const solvers::Twin twin = solvers::case_twin(mesh, spec, full);
    std::printf("case %s: %ld nodes, twin order %ld (%.0f s)\n", argv[1],
                static_cast<long>(mesh.nodes.rows()), static_cast<long>(twin.model.states()),
                seconds_since(t_all));

    // The generator's runs: TRAIN + HELD clean, then one of each effect kind.
    const auto t_gen = Clock::now();
    calibration::GeneratorOptions gopt;
    const core::CaseSpec gen = calibration::generator_case(spec, gopt);
    const mesh::TetMesh gmesh = mesh::mesh_case(gen);
    calibration::Instrumentation inst;
    inst.sensor_points = sensors;
    std::mt19937_64 rng = core::generator(seed, 0);
    std::vector<std::pair<std::string, calibration::InjectedEffect>> plan;
    for (int k = 0; k < train + held; ++k)
      plan.emplace_back("clean", calibration::InjectedEffect{});
    for (const auto& e : calibration::random_effect_of_each_kind(spec, gmesh, sensors, rng))
      plan.emplace_back(calibration::kind_name(e.kind), e);
    // A second draw of each kind, from a stream of its own and simulated last (the runs before
    // are those of before, to the digit): the changed-machine runs that choose c and e (observe
    // --changed).
    const std::size_t first_changed = plan.size();
    std::mt19937_64 changed_rng = core::generator(seed, 1);
    for (const auto& e : calibration::random_effect_of_each_kind(spec, gmesh, sensors, changed_rng))
      plan.emplace_back("changed " + std::string(calibration::kind_name(e.kind)), e);
    std::vector<Generated> runs;
    // The clean runs share one truth machine (mesh, probes' influences, step factors); an effect
    // that changes groups, materials or mechanics gets its own.
    std::optional<calibration::TruthMachine> machine;
    for (std::size_t k = 0; k < plan.size(); ++k) {
      const auto& [kind, effect] = plan[k];
      const core::DutyCycle duty = calibration::random_duty_cycle(hours, rng);
      const core::CaseSpec truth_spec =
          calibration::truth_case(gen, effect, duty, static_cast<int>(k));
      const std::string name = "gen_" + std::to_string(k);
      const io::MeasuredRun clean =
          calibration::clean_run(calibration::machine_for(machine, gmesh, truth_spec, inst),
                                 truth_spec, {effect}, gopt, name);
      Generated g{kind, calibration::with_noise(clean, gopt, rng), clean.displacement};
      g.measured.folder = name;
      runs.push_back(std::move(g));
      std::printf("%s: %s (%.0f s)\n", name.c_str(), kind.c_str(), seconds_since(t_gen));
      std::fflush(stdout);
    }

    // The calibration on the training runs, as observe --train runs it.
    const auto setup_with = [&](const Eigen::VectorXd& scale) {
      return [&twin, scale](const core::CaseSpec& c, const std::vector<std::string>& s,
                            const Eigen::MatrixXd& rows) {
        return cli_setup(twin, c, s, rows, scale);
      };
    };
    studies::SigmaCalibrationInput input{.declared = &spec,
                                         .twin = &twin,
                                         .mesh = &mesh,
                                         .setup = setup_with({}),
                                         .runs = {},
                                         .sensors = sensors,
                                         .drift_readings_every_s = probe_every_s,
                                         .truth_sigma_m = gopt.noise_displacement_m,
                                         .coverage = 0.95,
                                         .changed = {},
                                         .evidence_from_data = false,
                                         .progress = {}};
    for (int k = 0; k < train; ++k)
      input.runs.push_back(&runs[static_cast<std::size_t>(k)].measured);
    const auto t_cal = Clock::now();
    const studies::SigmaCalibration cal = studies::calibrate_observer_sigma(input);
    studies::SigmaCalibrationInput undeclared = input;
    undeclared.truth_sigma_m = 0;
    for (std::size_t k = first_changed; k < runs.size(); ++k)
      undeclared.changed.push_back(&runs[k].measured);
    const studies::SigmaCalibration cal_plain = studies::calibrate_observer_sigma(undeclared);
    // The terms gated (--changed-terms-after-alarm, --changed-terms-on-evidence), chosen so on
    // the same observation of the changed runs (ChangedMachineSigma::gates; always is `pick`).
    const std::vector<std::pair<const char*, const studies::GateChoice*>> gates{
        {"after the alarm", &cal_plain.changed->gates.at(2)},
        {"on evidence", &cal_plain.changed->gates.at(1)}};
    std::printf("calibration on %d training runs (%.0f s): factors", train, seconds_since(t_cal));
    for (Eigen::Index t = 0; t < cal.temperatures.drift_sigma_scale.size(); ++t)
      std::printf(" %s %.4g", cal.targets[static_cast<std::size_t>(t)].c_str(),
                  cal.temperatures.drift_sigma_scale(t));
    std::printf(" (noise not declared:");
    for (Eigen::Index t = 0; t < cal_plain.temperatures.drift_sigma_scale.size(); ++t)
      std::printf(" %.4g", cal_plain.temperatures.drift_sigma_scale(t));
    std::printf(")\n");
    const studies::ChangedMachineSigma& changed = *cal_plain.changed;
    const studies::SigmaTermsCandidate& pick = changed.pick();
    std::printf("chosen on %zu changed runs (noise not declared): c %g, e %g; out of reach:",
                changed.runs.size(), pick.correction_relative_sigma, pick.expansion_relative_sigma);
    for (std::size_t t = 0; t < changed.out_of_reach.size(); ++t)
      if (changed.out_of_reach[t]) std::printf(" %s", cal.targets[t].c_str());
    std::printf("; their coverage at c = e = 0 and at the choice:");
    for (Eigen::Index t = 0; t < changed.grid.front().score.coverage.size(); ++t)
      std::printf(" %s %.1f -> %.1f %%", cal.targets[static_cast<std::size_t>(t)].c_str(),
                  100 * changed.grid.front().score.coverage(t), 100 * pick.score.coverage(t));
    std::printf("\n");
    for (std::size_t g = 0; g < gates.size(); ++g) {
      const studies::SigmaTermsCandidate& gated_pick = gates[g].second->pick;
      std::printf("with the terms %s: c %g, e %g; their coverage at the choice:", gates[g].first,
                  gated_pick.correction_relative_sigma, gated_pick.expansion_relative_sigma);
      for (Eigen::Index t = 0; t < gated_pick.score.coverage.size(); ++t)
        std::printf(" %s %.1f %%", cal.targets[static_cast<std::size_t>(t)].c_str(),
                    100 * gated_pick.score.coverage(t));
      std::printf(
          "; the training runs' band %.2f (always on: %.2f; sum of RMS sigma / RMS error)\n",
          gates[g].second->training_width, cal_plain.changed->gates.at(0).training_width);
    }
    // Terms on evidence under every evidence setting (ChangedMachineSigma::evidence_settings).
    std::printf(
        "on evidence, by setting (time constant s, onset sigmas): c, e; the changed runs' "
        "coverage; the training runs' band\n");
    for (std::size_t k = 0; k < changed.evidence_settings.size(); ++k) {
      const studies::EvidenceChoice& e = changed.evidence_settings[k];
      std::printf("  %5g s %3g: c %g, e %g;", e.settings.time_s, e.settings.onset_sigmas,
                  e.choice.pick.correction_relative_sigma, e.choice.pick.expansion_relative_sigma);
      for (Eigen::Index t = 0; t < e.choice.pick.score.coverage.size(); ++t)
        std::printf(" %.1f", 100 * e.choice.pick.score.coverage(t));
      std::printf(" %%; %.2f%s%s\n", e.choice.training_width, e.reaches_goal ? " reaches" : "",
                  k == changed.evidence_chosen ? " (chosen)" : "");
    }
    if (cal.probed) {
      std::printf("with a probe cycle every %g s: factors", probe_every_s);
      for (Eigen::Index t = 0; t < cal.probed->drift_sigma_scale.size(); ++t)
        std::printf(" %.4g", cal.probed->drift_sigma_scale(t));
      std::printf("\n");
    }

    // The held-out runs, observed as observe --data observes them, scored before and after.
    Pooled clean, effect, clean_probed, effect_probed;
    const auto t_obs = Clock::now();
    for (std::size_t k = static_cast<std::size_t>(train); k < first_changed; ++k) {
      const Generated& g = runs[k];
      studies::ObserveInput in{&spec, &g.measured, &twin, sensors, setup_with({}), &mesh, 0.0};
      const studies::ObserveReport r = studies::observe_run(in);
      Eigen::MatrixXd truth = Eigen::MatrixXd::Constant(
          r.result.drift.rows(), r.result.drift.cols(), std::numeric_limits<double>::quiet_NaN());
      truth.leftCols(3) = g.truth.leftCols(3);
      const Eigen::MatrixXd measured =
          studies::drift_columns(g.measured, r.setup.target_names, "scored").readings;
      Pooled& p = g.kind == "clean" ? clean : effect;
      p.runs.push_back(r.result);
      p.truths.push_back(truth);
      p.measured.push_back(measured);
      if (probe_every_s > 0) {
        in.drift_readings_every_s = probe_every_s;
        const studies::ObserveReport rp = studies::observe_run(in);
        // Scored between readings, as the calibration scores them.
        const Eigen::MatrixXd read =
            studies::drift_readings(g.measured, rp.setup.target_names, probe_every_s).readings;
        const Eigen::MatrixXd between = studies::between_readings(truth, read);
        const Eigen::MatrixXd between_measured = studies::between_readings(measured, read);
        Pooled& pp = g.kind == "clean" ? clean_probed : effect_probed;
        pp.runs.push_back(rp.result);
        pp.truths.push_back(between);
        pp.measured.push_back(between_measured);
      }
    }
    std::printf("observed %zu held-out runs (%.0f s)\n\n", first_changed - train,
                seconds_since(t_obs));
    std::printf(
        "runs | target | samples | RMS error [um] | true drift in ±2σ, uncalibrated | "
        "calibrated | measured drift in the calibrated band (noise added) | factor | calibrated "
        "RMS "
        "sigma / RMS error\n");
    report("held-out clean, noise declared", clean, cal.temperatures.drift_sigma_scale,
           gopt.noise_displacement_m, cal.targets);
    report("held-out clean, noise not declared", clean, cal_plain.temperatures.drift_sigma_scale, 0,
           cal.targets);
    report("effect runs, noise declared", effect, cal.temperatures.drift_sigma_scale,
           gopt.noise_displacement_m, cal.targets);
    report("effect runs, noise not declared", effect, cal_plain.temperatures.drift_sigma_scale, 0,
           cal.targets);
    // c and e chosen on the changed runs, on the factors of the noise not declared.
    const auto with_choice = [&](const Pooled& p, const studies::SigmaTermsCandidate& choice,
                                 solvers::ChangedTermsGate gate) {
      Pooled out = p;
      for (solvers::ObserverRun& r : out.runs)
        r = studies::with_sigma(r, cal_plain.temperatures.drift_sigma_scale,
                                choice.correction_relative_sigma, choice.expansion_relative_sigma,
                                gate);
      return out;
    };
    const Eigen::VectorXd ones = Eigen::VectorXd::Ones(cal.temperatures.drift_sigma_scale.size());
    report("held-out clean, noise not declared, c and e of the changed runs",
           with_choice(clean, pick, solvers::ChangedTermsGate::always), ones, 0, cal.targets);
    report("effect runs, noise not declared, c and e of the changed runs",
           with_choice(effect, pick, solvers::ChangedTermsGate::always), ones, 0, cal.targets);
    for (std::size_t g = 0; g < gates.size(); ++g) {
      const std::string how = std::string(", c and e ") + gates[g].first;
      report("held-out clean, noise not declared" + how,
             with_choice(clean, gates[g].second->pick, gates[g].second->gate), ones, 0,
             cal.targets);
      report("effect runs, noise not declared" + how,
             with_choice(effect, gates[g].second->pick, gates[g].second->gate), ones, 0,
             cal.targets);
    }
    // The evidence setting the data chose, its pair, on the held-out runs.
    const studies::EvidenceChoice& data_evidence =
        changed.evidence_settings.at(changed.evidence_chosen);
    const auto reweighed = [&](const Pooled& p) {
      Pooled out = p;
      for (solvers::ObserverRun& r : out.runs)
        r = studies::with_evidence(std::move(r), data_evidence.settings);
      return out;
    };
    const Pooled clean_chosen = reweighed(clean), effect_chosen = reweighed(effect);
    char setting[96];
    std::snprintf(setting, sizeof setting, ", c and e on evidence (%g s, onset %g sigma)",
                  data_evidence.settings.time_s, data_evidence.settings.onset_sigmas);
    report(std::string("held-out clean, noise not declared") + setting,
           with_choice(clean_chosen, data_evidence.choice.pick,
                       solvers::ChangedTermsGate::on_evidence),
           ones, 0, cal.targets);
    report(std::string("effect runs, noise not declared") + setting,
           with_choice(effect_chosen, data_evidence.choice.pick,
                       solvers::ChangedTermsGate::on_evidence),
           ones, 0, cal.targets);
    // How often the readings show evidence of a change (the on-evidence gate's weight > 0), and
    // its mean weight, on the clean and the effect runs.
    for (const Pooled* p :
         std::initializer_list<const Pooled*>{&clean, &effect, &clean_chosen, &effect_chosen}) {
      double any = 0, sum = 0, n = 0;
      for (const solvers::ObserverRun& r : p->runs)
        for (const solvers::DriftSigmaTerms& t : r.sigma_terms) {
          const double w = solvers::changed_terms_weight(t, solvers::ChangedTermsGate::on_evidence);
          any += w > 0;
          sum += w;
          n += 1;
        }
      std::printf("%s runs%s: evidence weight > 0 on %.1f %% of the samples, mean %.3f\n",
                  p == &clean || p == &clean_chosen ? "held-out clean" : "effect",
                  p == &clean || p == &effect ? "" : setting, 100 * any / n, sum / n);
    }
    if (cal.probed) {
      report("held-out clean, probe cycle, noise declared", clean_probed,
             cal.probed->drift_sigma_scale, gopt.noise_displacement_m, cal.targets);
      report("effect runs, probe cycle, noise declared", effect_probed,
             cal.probed->drift_sigma_scale, gopt.noise_displacement_m, cal.targets);
    }
    std::printf("total %.0f s\n", seconds_since(t_all));
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench_studies_observer_sigma: " << e.what() << "\n";
    return 1;
  }
}
