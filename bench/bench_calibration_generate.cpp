// Writes measured-data sets with one undeclared effect, for `thermotwin calibrate`.
// Usage: bench_calibration_generate CASE KIND OUT_DIR [RUNS=3] [HOURS=2] [SEED=1]
//                                   [MESH_SCALE=0.8] [STEP_S=6]
//   HOURS: one length for every run, or one per run separated by commas (e.g. 2,6,8)
//   MESH_SCALE, STEP_S: the generator's mesh (bodies' max_edge times this) and time step; the
//   defaults (GeneratorOptions) are finer than any case; coarser ones make long runs on a large
//   mesh affordable (e.g. timing calibrate on the default SB-1)
//   KIND: none | ambient_temperature | heat_input | speed_dependent_convection |
//         temperature_dependent_heat | boundary_conductance | material_parameter | sensor_offset |
//         sensor_lag
// Writes OUT_DIR/run_<k>/ (meta.json + data.csv) and OUT_DIR/truth.json (the drawn effect).
// 1. Read the case; 2. mesh it finer (the generator's own mesh); 3. draw the effect and the duty
// cycles; 4. simulate each run with the effect on, add sensor noise, write it.
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "calibration/generator.hpp"
#include "core/rng.hpp"
#include "io/case_reader.hpp"
#include "mesh/mesher.hpp"

int main(int argc, char** argv) {
  using namespace tt;
  if (argc < 4) {
    std::cerr
        << "usage: bench_calibration_generate CASE KIND OUT_DIR [RUNS=3] [HOURS=2] [SEED=1]\n";
    return 2;
  }
  try {
    const std::string kind_text = argv[2];
    const std::filesystem::path out = argv[3];
    const int runs = argc > 4 ? std::stoi(argv[4]) : 3;
    std::vector<double> hours;
    if (argc > 5) {
      std::stringstream list(argv[5]);
      for (std::string item; std::getline(list, item, ',');) hours.push_back(std::stod(item));
    }
    if (hours.empty()) hours.push_back(2.0);
    if (hours.size() != 1 && static_cast<int>(hours.size()) != runs) {
      std::cerr << "HOURS: " << hours.size() << " lengths for " << runs << " runs\n";
      return 2;
    }
    const std::uint64_t seed = argc > 6 ? std::stoull(argv[6]) : 1;
    const core::CaseSpec declared = io::read_case(argv[1]);
    calibration::GeneratorOptions options;
    if (argc > 7) options.mesh_scale = std::stod(argv[7]);
    if (argc > 8) options.step_s = std::stod(argv[8]);
    const core::CaseSpec gen = calibration::generator_case(declared, options);
    const mesh::TetMesh m = mesh::mesh_case(gen);
    calibration::Instrumentation inst;
    inst.sensor_points = {"T02", "T05", "T08", "T11", "T14", "T17", "T19", "T23",
                          "T27", "T31", "T35", "T40", "T44", "T48", "T52", "T54"};
    std::mt19937_64 rng = core::generator(seed, 0);
    calibration::InjectedEffect effect;
    for (int k = 0; k <= static_cast<int>(calibration::EffectKind::sensor_lag); ++k)
      if (calibration::kind_name(static_cast<calibration::EffectKind>(k)) == kind_text)
        effect = calibration::random_effect(static_cast<calibration::EffectKind>(k), declared, m,
                                            inst.sensor_points, rng);
    if (kind_text != "none" && !effect.present) {
      std::cerr << "unknown effect kind '" << kind_text << "'\n";
      return 2;
    }
    std::filesystem::create_directories(out);
    for (int k = 0; k < runs; ++k) {
      const double h = hours[hours.size() == 1 ? 0 : static_cast<size_t>(k)];
      const core::DutyCycle duty = calibration::random_duty_cycle(h, rng);
      const core::CaseSpec truth = calibration::truth_case(gen, effect, duty, k);
      const io::MeasuredRun run = calibration::synthetic_run(m, truth, effect, inst, options,
                                                             "run " + std::to_string(k), rng);
      io::write_measured_run(out / ("run_" + std::to_string(k)), run);
      std::cerr << "wrote " << (out / ("run_" + std::to_string(k))).string() << "\n";
    }
    nlohmann::json t = {{"kind", effect.present ? calibration::kind_name(effect.kind) : "none"},
                        {"magnitude", effect.magnitude},
                        {"target", effect.target},
                        {"centre_m", {effect.centre(0), effect.centre(1), effect.centre(2)}},
                        {"follows_speed", effect.follows_speed}};
    std::ofstream(out / "truth.json") << t.dump(2) << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench_calibration_generate: " << e.what() << "\n";
    return 1;
  }
}
