// End to end through the CLI on the coarse SB-1 (order 1): `run` with the housing's surface
// vertices as candidates records their histories (candidates.csv, candidate_temperatures.csv),
// and `place --from` the run chooses among them with every method, for dy and dz, m = 1..6;
// `--methods observer_variance` places for the physics observer on the reduced model built on the
// fly (the vertices read through the basis rows) and writes it into placement.json as its schema
// says; a name that is not a method is refused. `fit --estimation` adds it to fit's methods.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "io/child_process.hpp"
#include "tests/common/output_schema.hpp"

namespace {

namespace fs = std::filesystem;

const fs::path kThermotwin = fs::path(TT_BINARY_DIR) / "thermotwin";
const fs::path kCoarse = fs::path(TT_SOURCE_DIR) / "cases" / "sb1_coarse.toml";

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs thermotwin with `args`, output (only this run's) into `log`; its exit status.
int thermotwin(std::vector<std::string> args, const fs::path& log) {
  args.insert(args.begin(), kThermotwin.string());
  fs::remove(log);
  return tt::io::run_program(args, {}, log);
}

int data_lines(const fs::path& csv) {
  std::ifstream in(csv);
  int n = 0;
  for (std::string line; std::getline(in, line);) n += !line.empty();
  return n - 1;  // without the header
}

TEST(PlaceCli, SurfaceVerticesOfTheHousingOnCoarseSb1) {
  const fs::path dir = fs::path(TT_BINARY_DIR) / "place_cli_scratch";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // The coarse case, without field files (not needed here), choosing among the housing's surface.
  std::string text = text_of(kCoarse);
  const auto outputs = text.find("[outputs]\n");
  ASSERT_NE(outputs, std::string::npos);
  text.insert(outputs + 10, "fields = false\n");
  text += "\n[placement]\ncandidates = \"surface\"\nbodies = [\"housing\"]\n";
  std::ofstream(dir / "case.toml") << text;

  ASSERT_EQ(
      thermotwin({"run", (dir / "case.toml").string(), "--out", (dir / "run").string(), "--quiet"},
                 dir / "run.log"),
      0)
      << text_of(dir / "run.log");
  const int n = data_lines(dir / "run" / "candidates.csv");
  EXPECT_GT(n, 1000) << "the housing of the coarse mesh has some 2000 surface vertices";
  EXPECT_EQ(data_lines(dir / "run" / "candidate_temperatures.csv"),
            data_lines(dir / "run" / "temperatures.csv"));

  ASSERT_EQ(thermotwin({"place", "--from", (dir / "run").string(), "--out",
                        (dir / "place").string(), "--quiet"},
                       dir / "place.log"),
            0)
      << text_of(dir / "place.log");
  const auto doc = nlohmann::json::parse(text_of(dir / "place" / "placement.json"));
  ASSERT_EQ(doc["candidates"].size(), static_cast<size_t>(n));
  for (const auto& c : doc["candidates"]) {
    const std::string name = c["name"];
    EXPECT_EQ(name, "v" + std::to_string(c["node"].get<int>()));
  }
  EXPECT_EQ(doc["samples"], 100);
  const std::set<std::string> methods{"histogram_mi", "gaussian_greedy", "gaussian_ga",
                                      "ksg_greedy",   "jmi_ksg",         "qr_pod",
                                      "correlation",  "grey_relational"};
  for (const std::string target : {"dy", "dz"}) {
    ASSERT_TRUE(doc["targets"].contains(target)) << target;
    const auto& by_method = doc["targets"][target]["methods"];
    for (const auto& method : methods) {
      ASSERT_TRUE(by_method.contains(method)) << target << " " << method;
      std::set<int> ms;
      for (const auto& s : by_method[method]) {
        ms.insert(s["m"].get<int>());
        EXPECT_EQ(s["ids"].size(), s["m"].get<size_t>());
        for (const auto& id : s["ids"]) EXPECT_TRUE(id.get<int>() >= 1 && id.get<int>() <= n);
      }
      EXPECT_EQ(ms, (std::set<int>{1, 2, 3, 4, 5, 6})) << target << " " << method;
    }
  }
  EXPECT_TRUE(fs::exists(dir / "place" / "candidates_mi.vtp"));
  EXPECT_EQ(doc["sensor_noise"], false);

  // On readings with the campaign's sensor noise: every set again, and the same sets from the
  // same seed.
  std::vector<nlohmann::json> noisy;
  for (const char* out : {"place_noisy_1", "place_noisy_2"}) {
    ASSERT_EQ(thermotwin({"place", "--from", (dir / "run").string(), "--out", (dir / out).string(),
                          "--sensor-noise", "--quiet"},
                         dir / "place.log"),
              0)
        << text_of(dir / "place.log");
    noisy.push_back(nlohmann::json::parse(text_of(dir / out / "placement.json")));
  }
  EXPECT_EQ(noisy[0]["sensor_noise"], true);
  for (const std::string target : {"dy", "dz"})
    for (const auto& method : methods) {
      const auto& a = noisy[0]["targets"][target]["methods"][method];
      const auto& b = noisy[1]["targets"][target]["methods"][method];
      ASSERT_EQ(a.size(), 6u) << target << " " << method;
      for (size_t k = 0; k < a.size(); ++k)
        EXPECT_EQ(a[k]["ids"], b[k]["ids"]) << target << " " << method;
    }
  // Placement for estimation beside the correlation ranking: the observer's posterior sigma of
  // each target falls with every sensor added.
  ASSERT_EQ(thermotwin({"place", "--from", (dir / "run").string(), "--out",
                        (dir / "place_observer").string(), "--methods",
                        "observer_variance,correlation", "--m-max", "3", "--quiet"},
                       dir / "place.log"),
            0)
      << text_of(dir / "place.log");
  EXPECT_TRUE(tt::test::matches_output_schemas("place", dir / "place_observer"));
  const auto observer = nlohmann::json::parse(text_of(dir / "place_observer" / "placement.json"));
  EXPECT_GT(observer["observer_variance"]["order"].get<int>(), 10);
  for (const std::string target : {"dy", "dz"}) {
    const auto& by_method = observer["targets"][target]["methods"];
    EXPECT_FALSE(by_method.contains("histogram_mi")) << "only the methods asked for";
    ASSERT_TRUE(by_method.contains("correlation"));
    const auto& sets = by_method["observer_variance"];
    ASSERT_EQ(sets.size(), 3u) << target;
    for (size_t k = 0; k < sets.size(); ++k) {
      EXPECT_EQ(sets[k]["m"], k + 1);
      EXPECT_EQ(sets[k]["score_kind"], "posterior_sigma_m");
      if (k > 0) EXPECT_LT(sets[k]["score"].get<double>(), sets[k - 1]["score"].get<double>());
    }
  }
  // Placement for detection on the same model: the observer's unknown heat inputs and its air,
  // no sensor offset; each greedy step makes more effects seen (or, once none can be, progress),
  // and an effect is unseen after it only when no candidate holds it beyond the bound.
  const auto& detection = observer["observer_detection"];
  EXPECT_EQ(detection["bound_sigmas"], 3.0);
  EXPECT_EQ(detection["sustain_s"], 900.0);
  ASSERT_GE(detection["effects"].size(), 2u);
  bool air = false;
  for (const auto& e : detection["effects"]) {
    air = air || e["name"] == "air";
    EXPECT_EQ(e["name"].get<std::string>().rfind("offset:", 0), std::string::npos) << e;
  }
  EXPECT_TRUE(air);
  ASSERT_FALSE(detection["greedy"].empty());
  EXPECT_LE(detection["greedy"].size(), 3u);  // --m-max
  EXPECT_GE(detection["greedy"][0]["effects_seen"].get<int>(), 1);
  for (size_t k = 1; k < detection["greedy"].size(); ++k)
    EXPECT_GE(detection["greedy"][k]["effects_seen"].get<int>(),
              detection["greedy"][k - 1]["effects_seen"].get<int>());
  for (const auto& name : detection["unseen"])
    for (const auto& e : detection["effects"])
      if (e["name"] == name && detection["greedy"].size() < 3u)
        EXPECT_LT(e["best_held_sigmas"].get<double>(), 3.0) << name;
  EXPECT_TRUE(detection["unseen_by_observer_variance"].contains("dy"));
  EXPECT_NE(thermotwin({"place", "--from", (dir / "run").string(), "--out",
                        (dir / "place_bad").string(), "--methods", "observer_varianse", "--quiet"},
                       dir / "place.log"),
            0);
  EXPECT_NE(text_of(dir / "place.log").find("'observer_varianse' is not a method"),
            std::string::npos)
      << text_of(dir / "place.log");
  EXPECT_FALSE(fs::exists(dir / "place_bad" / "placement.json"));
  if (!HasFailure()) fs::remove_all(dir);  // kept for a look when something failed
}

TEST(FitCli, PlacesForEstimationWhenAsked) {
  // `fit --estimation` adds placement for estimation (observer_variance, on the campaign's reduced
  // model) to the methods the sensor sets come from: one more column in each sensor-count table,
  // its sets fitted and tested as the others are; without the flag, none. With --full there is
  // no reduced model, so the flag is refused before any work.
  const fs::path dir = fs::temp_directory_path() / "tt_fit_estimation";
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const bool estimation : {false, true}) {
    const fs::path out = dir / (estimation ? "with" : "without");
    std::vector<std::string> args{"fit", kCoarse.string(), "--out", out.string(), "--hours",
                                  "2",   "--quick"};
    // Without --quiet the long part says how far it is: a line per fitting run's duty cycle.
    args.push_back(estimation ? "--estimation" : "--quiet");
    ASSERT_EQ(thermotwin(args, dir / "fit.log"), 0) << text_of(dir / "fit.log");
    if (estimation)
      EXPECT_NE(text_of(dir / "fit.log")
                    .find("thermotwin: fit: placement for estimation: the covariance stepped "
                          "along duty cycle 4 of 4"),
                std::string::npos)
          << text_of(dir / "fit.log");
    EXPECT_TRUE(tt::test::matches_output_schemas("fit", out));
    for (const char* target : {"dy", "dz"}) {
      const std::string table = text_of(out / ("sensor_count_" + std::string(target) + ".csv"));
      const std::string header = table.substr(0, table.find('\n'));
      EXPECT_EQ(header.find("observer_variance_test_sm_um") != std::string::npos, estimation)
          << target << ": " << header;
      EXPECT_NE(header.find("gaussian_greedy_test_sm_um"), std::string::npos) << header;
      EXPECT_EQ(data_lines(out / ("sensor_count_" + std::string(target) + ".csv")), 6) << target;
    }
  }
  EXPECT_NE(thermotwin({"fit", kCoarse.string(), "--out", (dir / "full").string(), "--full",
                        "--estimation", "--quiet"},
                       dir / "fit.log"),
            0);
  EXPECT_NE(text_of(dir / "fit.log").find("--estimation"), std::string::npos)
      << text_of(dir / "fit.log");
  EXPECT_FALSE(fs::exists(dir / "full"));
  if (!HasFailure()) fs::remove_all(dir);
}

TEST(PlaceCli, PlacesForDetectionOfTheCataloguesEffectsWhenAsked) {
  // `place --catalogue-detection` on the coarse SB-1's named points (54, marched on the reduced
  // model on their rows): every kind of the catalogue's heat-flow effects at its size, each
  // effect's best candidate, a greedy whose kinds seen grow with each sensor and never exceed the
  // kinds, and the kinds each method's largest set sees. It says how far the march is; without the
  // flag there is no catalogue_detection.
  const fs::path dir = fs::temp_directory_path() / "tt_place_catalogue";
  fs::remove_all(dir);
  fs::create_directories(dir);
  ASSERT_EQ(thermotwin({"place", kCoarse.string(), "--out", (dir / "place").string(), "--methods",
                        "correlation", "--m-max", "3", "--catalogue-detection"},
                       dir / "place.log"),
            0)
      << text_of(dir / "place.log");
  EXPECT_NE(text_of(dir / "place.log")
                .find("thermotwin: place: the catalogue's effects for detection 100 %"),
            std::string::npos)
      << text_of(dir / "place.log");
  EXPECT_NE(text_of(dir / "place.log")
                .find("thermotwin: place: placement for detection: the calibration catalogue's "
                      "effects"),
            std::string::npos)
      << text_of(dir / "place.log");
  EXPECT_TRUE(tt::test::matches_output_schemas("place", dir / "place"));
  const auto doc = nlohmann::json::parse(text_of(dir / "place" / "placement.json"));
  ASSERT_TRUE(doc.contains("catalogue_detection"));
  const auto& d = doc["catalogue_detection"];
  EXPECT_EQ(d["model"], "reduced on the candidates' rows");
  EXPECT_EQ(d["bound_sigmas"], 3.0);
  const std::vector<std::string> kinds{"ambient_temperature",        "heat_input",
                                       "speed_dependent_convection", "temperature_dependent_heat",
                                       "boundary_conductance",       "material_parameter"};
  std::size_t effects = 0;
  for (const auto& kind : kinds) {
    ASSERT_TRUE(d["effects_per_kind"].contains(kind)) << kind;
    effects += d["effects_per_kind"][kind].get<std::size_t>();
  }
  EXPECT_EQ(d["effects_per_kind"].size(), kinds.size());
  ASSERT_EQ(d["effects"].size(), effects);
  EXPECT_GT(d["effects_per_kind"]["heat_input"].get<int>(), 100);  // patches under two laws
  int beyond = 0;                                                  // effects some candidate sees
  for (const auto& e : d["effects"]) beyond += e["best_held_sigmas"].get<double>() >= 3.0;
  ASSERT_EQ(d["greedy"].size(), 3u);
  double before = 0;
  for (const auto& step : d["greedy"]) {
    EXPECT_GT(step["kinds_seen"].get<double>(), before) << step;
    before = step["kinds_seen"].get<double>();
    EXPECT_LE(step["effects_seen"].get<int>(), beyond);
  }
  EXPECT_LE(before, static_cast<double>(kinds.size()));
  for (const std::string target : {"dy", "dz"}) {
    const double seen = d["kinds_seen_by_method"][target]["correlation"].get<double>();
    EXPECT_GT(seen, 0.0) << target;
    EXPECT_LE(seen, static_cast<double>(kinds.size())) << target;
  }
  ASSERT_EQ(thermotwin({"place", kCoarse.string(), "--out", (dir / "without").string(), "--methods",
                        "correlation", "--m-max", "2", "--quiet"},
                       dir / "place.log"),
            0);
  EXPECT_FALSE(nlohmann::json::parse(text_of(dir / "without" / "placement.json"))
                   .contains("catalogue_detection"));
  // The sizes on the command line: each kind asked at twice its default size moves every reading
  // twice as far (the catalogue's responses are linear in their parameter), and the file says so.
  ASSERT_EQ(thermotwin({"place",
                        kCoarse.string(),
                        "--out",
                        (dir / "twice").string(),
                        "--methods",
                        "correlation",
                        "--m-max",
                        "3",
                        "--catalogue-detection",
                        "--quiet",
                        "--detect-heat-w",
                        "10",
                        "--detect-film-share",
                        "0.5",
                        "--detect-source-per-k",
                        "0.04",
                        "--detect-material-change",
                        "0.2",
                        "--detect-air-k",
                        "2"},
                       dir / "place.log"),
            0)
      << text_of(dir / "place.log");
  const auto twice =
      nlohmann::json::parse(text_of(dir / "twice" / "placement.json"))["catalogue_detection"];
  EXPECT_EQ(twice["sizes"], nlohmann::json({{"heat_W", 10.0},
                                            {"film_share", 0.5},
                                            {"source_coefficient_per_K", 0.04},
                                            {"material_change", 0.2},
                                            {"air_K", 2.0}}));
  EXPECT_EQ(d["sizes"]["heat_W"], 5.0);
  ASSERT_EQ(twice["effects"].size(), d["effects"].size());
  for (std::size_t e = 0; e < d["effects"].size(); ++e)
    EXPECT_NEAR(twice["effects"][e]["best_held_sigmas"].get<double>(),
                2 * d["effects"][e]["best_held_sigmas"].get<double>(),
                1e-9 * (1 + d["effects"][e]["best_held_sigmas"].get<double>()))
        << d["effects"][e];
  // A size that is no size, or one without the detection it sizes: refused, nothing written.
  for (const std::vector<std::string>& extra :
       {std::vector<std::string>{"--catalogue-detection", "--detect-heat-w", "0"},
        std::vector<std::string>{"--catalogue-detection", "--detect-air-k", "nan"},
        std::vector<std::string>{"--detect-film-share", "0.5"}}) {
    std::vector<std::string> cli{
        "place",     kCoarse.string(), "--out",  (dir / "refused").string(),
        "--methods", "correlation",    "--quiet"};
    cli.insert(cli.end(), extra.begin(), extra.end());
    EXPECT_NE(thermotwin(cli, dir / "refused.log"), 0) << extra.back();
    EXPECT_NE(text_of(dir / "refused.log").find(extra[extra.size() - 2]), std::string::npos)
        << text_of(dir / "refused.log");
    EXPECT_FALSE(fs::exists(dir / "refused"));
  }
  if (!HasFailure()) fs::remove_all(dir);
}

}  // namespace
